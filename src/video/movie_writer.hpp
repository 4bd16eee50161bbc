#pragma once
// Writes 8-bit RGB(A) frames as an H.264 (yuv420p) fragmented MP4 that stays readable up to its last
// flushed fragment if the process dies.
#include <memory>
#include <string>

#include <optional>

#include "core/image.hpp"
#include "video/packet_checksum.hpp"
#include "video/video_settings.hpp"

namespace panoptes::video {

class MovieReader;

/// One movie being written. Frames must all have the size given at construction. Odd sizes are
/// padded (edge pixels repeated) to the even size H.264 4:2:0 needs; padded_width()/padded_height()
/// report it so the manifest can record the padding and readers crop it off.
/// Memory: an intra-only writer (gop 1) borrows an x264 encoder for each append() from a pool shared
/// by every intra-only movie of its size and settings (one encoder per frame being encoded at once,
/// e.g. per thread), so an open writer holds ~1 MB; with gop > 1 the encoder lives as long as the
/// writer (~18-25 MB at 920x896). Appends to different writers may run concurrently. See docs/formats.md.
class MovieWriter {
 public:
  /// Creates (or truncates) the file. Throws FileError if it cannot be created, Error on bad settings.
  MovieWriter(const std::string& path, int width, int height, const VideoSettings& settings = {});
  /// Writes to `fd`, an empty regular file opened for writing (taken over: closed by the writer, also
  /// when the constructor throws); `path` only names it in messages. The store opens its movies this
  /// way, relative to the database directory and without following links. With `identity`, every
  /// frame's checksum message also carries it and the frame's index (packet_checksum.hpp, version 2),
  /// so readers can tell this movie's frames from any other's. `bind_parameter_sets`: the identity the
  /// frames carry has the CRC of the stream's SPS/PPS folded in (bind_parameter_sets(), frame-check
  /// scheme 3), so damage to the avcC's parameter sets shows on every frame.
  MovieWriter(int fd, const std::string& path, int width, int height, const VideoSettings& settings = {},
              const std::optional<MovieIdentity>& identity = std::nullopt, bool bind_parameter_sets = false);
  ~MovieWriter();  ///< Closes the movie if still open; never throws.
  MovieWriter(const MovieWriter&) = delete;
  MovieWriter& operator=(const MovieWriter&) = delete;

  /// Copies the first `count` frames of `source` into this movie as they are (no re-encoding, so they
  /// decode exactly as in the source): a restarted run continues its movies this way. Only before the
  /// first append; the source must have been written with the same size and settings (its stream
  /// header must equal this movie's) and hold `count` intact frames. Throws Error naming the source
  /// otherwise; FileError if writing fails.
  void copy_frames(const MovieReader& source, int count);
  /// Encodes one frame (3 or 4 channels). Throws Error if its size differs from the movie's,
  /// FileError if writing fails (e.g. disk full).
  void append(const Image& frame);
  /// Makes every appended frame durable in the file: drains the encoder's delay and writes a
  /// fragment. After flush() returns, a reader sees frames_written() frames even if the process dies.
  void flush();
  /// Writes the trailer and closes the file. Further appends throw.
  void close();

  int frames_written() const;
  int width() const;
  int height() const;
  int padded_width() const;
  int padded_height() const;
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace panoptes::video
