// The fragment indexer (web/mp4_fragments.hpp): what `panoptes serve` runs on a movie for
// /api/index/C/T.json and export-web on every movie it copies. Besides crashes and sanitizer reports,
// a finding is an index that does not describe the file (a fragment outside it, overlapping or out of
// order, frame numbers that do not add up) and a walk that does not end (libFuzzer's -timeout; issue
// 31: a 64-bit box size of 2^64-16 looped forever). Every exception is accepted.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "fuzz/fuzz_support.hpp"
#include "web/mp4_fragments.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  const auto path = fuzz::write_scratch("movie.mp4", data, size);
  web::FragmentIndex index;
  try {
    index = web::index_fragments(path);
  } catch (const std::exception&) {
    return 0;
  }
  const auto fail = [](const char* what) {
    std::fprintf(stderr, "mp4_fragments: %s\n", what);
    std::abort();
  };
  if (index.file_size != size) fail("file_size is not the file's size");
  if (index.init_size > size) fail("init segment beyond the file");
  std::uint64_t end = index.init_size;
  long long next = 0;
  for (const auto& f : index.fragments) {
    if (f.offset < end) fail("fragment overlaps what comes before it");
    if (f.size > size || f.offset > size - f.size) fail("fragment beyond the file");
    if (f.first_frame != next || f.frames < 0) fail("frame numbers do not add up");
    if (std::uint64_t(f.frames) > f.size) fail("more samples than bytes");
    end = f.offset + f.size;
    next += f.frames;
  }
  return 0;
}
