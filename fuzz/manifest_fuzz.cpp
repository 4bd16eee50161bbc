// The manifest reader (panoptes.json, with the camera table it names): what `panoptes info` and the
// player read first from a database anyone may have written. The scratch directory holds the camera
// table of the seed database (fuzz_seeds writes the same deterministic one), so a manifest that
// refers to it parses all the way through.
// The parser belongs to the store (issue 15 part A); here a crash or a sanitizer report is a finding,
// and every exception is accepted (message quality is tested by the store's own tests).
#include <exception>

#include "fuzz/fuzz_support.hpp"
#include "store/manifest.hpp"
#include "store/synthetic.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  static const bool prepared = [] {
    store::SyntheticOptions o;
    o.cameras = 3, o.tasks = 2, o.frames = 2, o.width = 48, o.height = 32, o.overwrite = true, o.threads = 1;
    store::write_synthetic_database(fuzz::scratch_dir() / "db", o);
    return true;
  }();
  (void)prepared;
  const auto path = fuzz::scratch_dir() / "db" / "panoptes.json";
  fuzz::write_scratch("db/panoptes.json", data, size);
  try {
    (void)store::read_manifest(path);
  } catch (const std::exception&) {
  }
  return 0;
}
