#pragma once
// The stream index of a static site exported from a packed database (docs/web.md, "A static site
// from a packed database"): where each stream's init segment and fragments lie in the pack files,
// in a few binary files of fixed-size entries, so that a player served by any static host or object
// store (no Panoptes server) finds one stream with one HTTP Range request, computed from the stream
// number alone. Shard k (`api/streams/k.bin`) holds streams [k * kStreamsPerShard, ...): a 64-byte
// header, one entry per stream, then the frame numbers of damaged frames.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace panoptes::web {

inline constexpr char kStreamIndexMagic[9] = "PNPTSTIX";
inline constexpr std::uint32_t kStreamIndexVersion = 1;
inline constexpr std::uint32_t kStreamIndexHeaderBytes = 64;
inline constexpr std::uint32_t kStreamEntryHeaderBytes = 32;
inline constexpr std::uint32_t kStreamFragmentBytes = 16;
/// Streams per shard file: 10^6 streams are 16 files; a shard of 5-frame streams is 7 MB.
inline constexpr std::int64_t kStreamsPerShard = 65536;
/// A fragment names its pack in 16 bits and its offset in 48 (256 TiB).
inline constexpr int kStreamIndexMaxPacks = 65536;
inline constexpr std::uint64_t kStreamIndexMaxOffset = (std::uint64_t(1) << 48) - 1;

/// Bytes of one entry: the header and one 16-byte slot per frame (a stream's fragments hold at least
/// one frame each and start at frame 0, so `frames` slots hold any stream's fragments).
inline std::uint32_t stream_entry_bytes(int frames) {
  return kStreamEntryHeaderBytes + kStreamFragmentBytes * std::uint32_t(frames);
}

/// One stream's byte ranges, as the index stores them.
struct StreamIndexEntry {
  struct Range {
    std::uint32_t pack = 0;  ///< position in the site's pack list (database.json stream_index.packs)
    std::uint64_t offset = 0;
    std::uint32_t size = 0;
    std::uint32_t frames = 0;  ///< 0 for the init segment
  };
  Range init;                          ///< meaningless without fragments
  std::vector<Range> fragments;        ///< in frame order, contiguous from frame 0; empty = missing
  std::vector<std::uint32_t> damaged;  ///< frames that fail the database's frame checks, ascending
};

/// Writes one shard: entries are added in stream order, then finish() writes the damaged-frame list
/// and the header. Throws FileError naming the file and the value on a write error or an entry the
/// format cannot hold (more fragments than `frames`, a pack number or offset out of range).
class StreamIndexWriter {
 public:
  StreamIndexWriter(const std::filesystem::path& file, std::int64_t first_stream, std::int64_t streams,
                    std::int64_t total_streams, int frames, int packs);
  void add(const StreamIndexEntry& entry);
  void finish();

 private:
  std::filesystem::path file_;
  std::ofstream out_;
  std::int64_t first_ = 0, streams_ = 0, total_ = 0, added_ = 0;
  int frames_ = 0, packs_ = 0;
  std::vector<std::uint32_t> damaged_;
};

/// Reads the entry of `stream` from a shard file, checking the header and the entry as the web
/// player does (movies.js). Throws FileError naming the file and the value otherwise.
StreamIndexEntry read_stream_index_entry(const std::filesystem::path& file, std::int64_t stream);

}  // namespace panoptes::web
