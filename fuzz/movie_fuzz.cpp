// The movie reader (fragmented MP4 / H.264 through FFmpeg): what the player opens for every stream
// of a database. Opens the input as a movie and decodes up to 8 frames from both ends. The reader
// belongs to the video module (issue 15 part A): here a crash, a hang or a sanitizer report is a
// finding; every exception is accepted. Read twice: as a lone movie, and with a scheme-3 database's
// frame checks (parameter sets bound to every frame's identity).
#include <algorithm>
#include <exception>

#include "fuzz/fuzz_support.hpp"
#include "video/movie_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  const auto path = fuzz::write_scratch("movie.mp4", data, size);
  try {
    video::MovieReader reader(path.string());
    const int n = reader.frame_count();
    video::YuvFrame frame;
    for (int i = 0; i < std::min(n, 4); ++i) reader.read(i, frame);
    for (int i = std::max(0, n - 4); i < n; ++i) reader.read(i, frame);
  } catch (const std::exception&) {
  }
  // As a database that records frame-check scheme 3 opens it (issue 44): the parameter sets of a
  // hostile avcC are parsed and bound, every packet's checksum message inspected.
  try {
    video::FrameChecks checks;
    checks.required = true;
    checks.parameter_sets = true;
    video::MovieReader reader(path.string(), checks);
    (void)reader.check_frames();
    video::YuvFrame frame;
    if (reader.frame_count() > 0) reader.read(0, frame);
  } catch (const std::exception&) {
  }
  return 0;
}
