// The volume readers of `panoptes render`: NumPy .npy and VTK legacy .vtk. The first byte picks the
// reader (even: .npy, odd: .vtk), the rest is the file. Any bytes give a volume or a FileError.
#include "app/volume_file.hpp"
#include "core/error.hpp"
#include "fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string file = panoptes::fuzz::as_string(data + 1, size - 1);
  try {
    if (data[0] % 2 == 0) (void)panoptes::app::parse_npy(file, "fuzz.npy");
    else (void)panoptes::app::parse_vtk(file, "fuzz.vtk");
  } catch (const panoptes::Error&) {
  }
  return 0;
}
