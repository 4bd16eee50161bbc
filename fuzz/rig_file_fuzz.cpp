// Explicit camera files (rig.spec = "file:PATH", text or JSON): any bytes give a rig or a FileError.
#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  const auto path = fuzz::write_scratch("cameras.txt", data, size);
  const camera::Domain domain{{0, 0, 0}, {1, 2, 3}};
  try {
    (void)camera::read_rig_file(path.string(), domain);
  } catch (const Error&) {
  }
  return 0;
}
