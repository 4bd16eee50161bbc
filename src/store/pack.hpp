#pragma once
// The packed layout of a database (docs/formats.md, "Packed layout"): per writing rank and output
// segment one pack file (`packs/s<segment>-r<rank>.pack`: an init segment, then fragments appended)
// and one index (`packs/s<segment>-r<rank>.idx`: a header with the rank's cameras, then one round of
// fixed-size records per flush, one record per (camera, task) of the rank). A stream is the init
// segment followed by its fragments: a standard fragmented MP4 cut out by byte ranges.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "store/safe_file.hpp"
#include "video/movie_reader.hpp"

namespace panoptes::store {

/// Index file layout constants (little-endian; see docs/formats.md).
inline constexpr char kPackIndexMagic[9] = "PNPTPIDX";
inline constexpr std::uint32_t kPackIndexVersion = 1;
inline constexpr std::size_t kPackIndexHeaderFixed = 64;  ///< before the camera list
inline constexpr std::size_t kPackRecordBytes = 24;
/// The directory of the packs inside a database.
inline constexpr const char* kPackDirectory = "packs";

/// File names of the pack and the index of (segment, rank), relative to the packs directory.
std::string pack_file_name(int segment, int rank);
std::string pack_index_name(int segment, int rank);

/// One record of an index round: the fragment of one stream written since the previous round.
struct PackRecord {
  std::uint64_t offset = 0;  ///< byte offset of the fragment (moof) in the pack; 0 with frames 0
  std::uint32_t size = 0;    ///< bytes of moof + mdat
  std::uint32_t first_frame = 0;
  std::uint32_t frames = 0;  ///< 0: the stream got no fragment in this round
};

/// CRC-32 check word of a record of stream id `stream` (camera * tasks + task).
std::uint32_t pack_record_check(const PackRecord& r, std::uint32_t stream);

/// Writes one pack and its index. append() may run concurrently; write_round() must not run
/// concurrently with anything. Creates both files (truncating leftovers of a killed earlier attempt
/// at the same segment, which no manifest names).
class PackWriter {
 public:
  /// `cameras`: the cameras this writer owns (any order, no duplicates); `tasks`: the database's task
  /// count; `first_frame`: the first frame of this segment; init: the init segment with its time scale.
  PackWriter(int packs_dir_fd, const std::filesystem::path& packs_dir, int segment, int rank,
             std::vector<int> cameras, int tasks, int first_frame, const std::vector<std::uint8_t>& init,
             std::uint32_t timescale, std::uint32_t frame_ticks);
  ~PackWriter();
  PackWriter(const PackWriter&) = delete;
  PackWriter& operator=(const PackWriter&) = delete;

  /// Appends bytes (whole fragments) to the pack; returns the offset of the first. Thread-safe.
  std::uint64_t append(const std::uint8_t* data, std::size_t size);
  /// Writes one index round: records[slot * tasks + task], slot = position of the camera in
  /// cameras() (ascending). Call only after every byte the records name was appended.
  void write_round(const std::vector<PackRecord>& records);

  const std::vector<int>& cameras() const { return cameras_; }  ///< ascending
  /// Position of `camera` in cameras(), or -1.
  int slot(int camera) const;
  std::uint64_t bytes() const;
  const std::filesystem::path& pack_path() const { return pack_path_; }

 private:
  std::filesystem::path pack_path_, index_path_;
  FileHandle pack_, index_;
  std::vector<int> cameras_;
  int tasks_ = 0;
  std::uint64_t end_ = 0;  // bytes in the pack
  std::uint64_t index_end_ = 0;
  std::mutex mutex_;
};

/// The parsed header of one index and where its rounds are.
struct PackIndexInfo {
  std::filesystem::path pack, index;  ///< full paths
  int segment = 0, rank = 0, tasks = 0;
  std::uint32_t first_frame = 0, timescale = 0, frame_ticks = 0;
  std::uint64_t init_offset = 0, init_size = 0;
  std::uint64_t header_bytes = 0;
  std::uint64_t rounds = 0;      ///< complete rounds in the index file
  std::uint64_t pack_size = 0;   ///< bytes of the pack when the index was read
  std::vector<int> cameras;      ///< ascending
  /// Position of `camera` in cameras, or -1.
  int slot(int camera) const;
  std::uint64_t round_bytes() const { return std::uint64_t(cameras.size()) * std::uint64_t(tasks) * kPackRecordBytes; }
  /// Byte offset in the index of the record of (slot, task) in round k.
  std::uint64_t record_offset(std::uint64_t round, int slot, int task) const {
    return header_bytes + round * round_bytes() + (std::uint64_t(slot) * std::uint64_t(tasks) + std::uint64_t(task)) * kPackRecordBytes;
  }
};

/// Reads and checks an index header (magic, version, CRC, camera list, init range within the pack).
/// `segment`, `rank`, `tasks`, `cameras_total` are what the manifest says. Throws FileError naming the
/// index and the value.
PackIndexInfo read_pack_index(int packs_dir_fd, const std::filesystem::path& packs_dir, int segment, int rank, int tasks,
                              int cameras_total);

/// Reads the records of one stream from an index (one pread per round). Records that name bytes past
/// the pack's end (a tail written after the pack data it names was lost) end the list. Throws
/// FileError on a damaged record (check word) or an index that cannot be read.
std::vector<PackRecord> read_stream_records(int index_fd, const PackIndexInfo& info, int camera, int task);

/// One stream of a packed database as byte ranges: what a web server serves or a static player
/// fetches. pieces[0] is the init segment (frames 0); then one piece per fragment in frame order.
struct PackedStream {
  struct Piece {
    std::filesystem::path file;  ///< the pack holding it
    std::uint64_t offset = 0, size = 0;
    int first_frame = 0, frames = 0;
  };
  std::vector<Piece> pieces;
  int frames() const;  ///< frames covered by the fragments
  /// For video::MovieReader.
  std::vector<video::FilePiece> file_pieces() const;
};

/// Chooses a stream's fragments from its records across segments (each list: the records of one
/// segment's pack, in round order): a record is used when it starts at the frame where the frames
/// chosen so far end, after dropping chosen fragments at or after its first frame (a later segment
/// continues from its first frame). Ranges must lie inside their pack and not overlap the init segment
/// or each other; throws FileError naming the pack otherwise.
PackedStream assemble_stream(const std::vector<std::pair<const PackIndexInfo*, std::vector<PackRecord>>>& segments,
                             int camera, int task);

}  // namespace panoptes::store
