// The headless player's script parser: any text gives commands or a panoptes::Error naming the line.
#include "core/error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "player/headless.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)panoptes::player::parse_script(panoptes::fuzz::as_string(data, size), "fuzz.script");
  } catch (const panoptes::Error&) {
  }
  return 0;
}
