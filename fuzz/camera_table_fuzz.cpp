// The binary camera table (cameras.<crc32>.bin). The CRC-32 in the header is recomputed for each
// input and the expected size / count are taken from the input, so mutations reach the column
// decoder instead of stopping at the checksum. The decoder belongs to the store (issue 15 part A):
// here a crash or a sanitizer report is a finding; every exception is accepted.
#include <cstring>
#include <exception>
#include <string>

#include "fuzz/fuzz_support.hpp"
#include "store/camera_table.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  std::string bytes = fuzz::as_string(data, size);
  store::CameraTableRef ref;
  ref.file = "cameras.fuzz.bin";
  ref.bytes = bytes.size();
  ref.navigation = size % 2 == 1;
  if (bytes.size() >= 32) {
    const std::uint32_t crc = store::crc32(bytes.data() + 16, bytes.size() - 16);
    std::memcpy(bytes.data() + 12, &crc, 4);
    ref.crc32 = crc;
    std::uint64_t count = 0;
    std::memcpy(&count, bytes.data() + 24, 8);
    ref.cameras = std::int64_t(count & 0x7fffffffffffffffULL);
  }
  store::Manifest m;
  try {
    store::decode_camera_table(bytes, ref, "fuzz.bin", m);
  } catch (const std::exception&) {
  }
  return 0;
}
