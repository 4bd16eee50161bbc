#pragma once
// Reads a movie written by MovieWriter (or any H.264 MP4): exact random access and sequential decode.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/image.hpp"
#include "video/packet_checksum.hpp"

namespace panoptes::video {

/// A decoded frame as planar YUV 4:2:0 (BT.601 limited range, as written), ready for GPU upload.
/// Planes are tightly packed: y has width*height bytes, u and v ((width+1)/2)*((height+1)/2).
struct YuvFrame {
  int width = 0, height = 0;
  int index = -1;  ///< frame number in the movie
  std::vector<std::uint8_t> y, u, v;
};

/// A frame whose data is damaged: the decoder concealed errors in it, or in a frame it is predicted
/// from. Readers show such a frame as damaged, never as good (and never another frame in its place).
class DamagedFrameError : public Error {
 public:
  using Error::Error;
};

/// What a reader demands of every frame (the store fills it in from what the manifest records).
struct FrameChecks {
  /// The movie was written with version-2 checksum messages (packet_checksum.hpp): every frame must
  /// carry one whose CRC matches, whose identity is `identity` and whose frame index is the frame's,
  /// at the timestamp its index gives (index × frame duration). A frame failing any of these is
  /// damaged. False (a movie whose database records nothing, or any other movie): checksums are
  /// checked when one of the movie's first packets carries a checksum message (good or not), and
  /// frames are otherwise taken as they come.
  bool required = false;
  MovieIdentity identity{};
  /// Frame-check scheme 3: the frames carry `identity` bound to the CRC of the stream's parameter sets
  /// (bind_parameter_sets()), computed here from the movie's own avcC. A damaged SPS or PPS (outside
  /// every frame's CRC, yet it changes every decoded picture: issue 44) then fails every frame.
  bool parameter_sets = false;
};

/// One byte range of a file: a piece of a movie stored inside a larger file (a packed database).
struct FilePiece {
  std::string path;
  std::uint64_t offset = 0, size = 0;
};

/// An open movie. Not thread-safe: use one reader per thread.
class MovieReader {
 public:
  /// Opens the file and indexes its packets (no decoding). Throws FileError if the file is missing,
  /// not a movie, or holds no decodable video stream. A truncated movie opens with the frames it has.
  explicit MovieReader(const std::string& path, const FrameChecks& checks = {});
  /// Opens the movie that is the concatenation of `pieces` (a fragmented MP4 cut into byte ranges:
  /// init segment first, then its fragments in order), read through a virtual file over them; `name`
  /// names it in messages (path()). Throws FileError as above, and when a range lies past the end of
  /// its file. Everything else (index, checks, truncation) works as for a whole file.
  MovieReader(const std::vector<FilePiece>& pieces, const std::string& name, const FrameChecks& checks = {});
  ~MovieReader();
  MovieReader(const MovieReader&) = delete;
  MovieReader& operator=(const MovieReader&) = delete;

  /// Crops decoded frames to width x height (to remove the padding of odd sizes; see the manifest).
  /// Throws Error if larger than the coded size.
  void set_crop(int width, int height);

  int frame_count() const;
  double fps() const;
  double duration() const;  ///< seconds: frame_count() / fps()
  int width() const;        ///< after cropping
  int height() const;
  int coded_width() const;   ///< size of the decoded pictures, before cropping
  int coded_height() const;
  /// True if frame `index` is a keyframe (decoding can start there).
  bool is_keyframe(int index) const;
  const std::string& path() const;

  /// Decodes exactly frame `index` (seeks to the keyframe at or before it, decodes forward; consecutive
  /// indices decode without seeking). Throws Error if index is out of range or the frame is unreadable,
  /// DamagedFrameError if the decoder had to conceal damage in it or in a frame it predicts from.
  void read(int index, YuvFrame& out);
  Image read_rgba(int index);
  /// The compressed packet of frame `index` exactly as stored (no decoding), for copying it into
  /// another movie (MovieWriter::copy_frames). Throws Error if index is out of range, FileError if
  /// the file cannot be read.
  void read_packet(int index, std::vector<std::uint8_t>& out) const;
  /// The stream's global header (for H.264 in MP4: the avcC record with SPS and PPS).
  const std::vector<std::uint8_t>& stream_header() const;
  /// True when every frame's packet comes in presentation order (no B-frames), so frames 0..n-1 are
  /// the first n packets.
  bool in_decode_order() const;
  /// The frames that fail the frame checks (checksum, identity, index, timestamp), found without
  /// decoding: reads every packet once. Empty for a movie without checksums (checks not required).
  /// Throws FileError if the file cannot be read.
  std::vector<int> check_frames();
  /// Packets sent to the decoder since open (a measure of decoding work: reading frames i, i+1, ...
  /// in order costs one packet each; a random read costs the distance from its keyframe plus one).
  std::int64_t packets_decoded() const;
  /// Converts a decoded frame to RGBA (for screenshots, tests, export; not the display path).
  static Image to_rgba(const YuvFrame& frame);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace panoptes::video
