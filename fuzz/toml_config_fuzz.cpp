// TOML configurations of `panoptes run` (in-situ sections + the seismic solver's) and `panoptes
// seismic`: any text gives a configuration or a panoptes::Error; any other exception is a bug (the
// user would see e.g. "std::out_of_range" or "bad_alloc" instead of the key at fault).
#include <string>
#include <vector>

#include "core/error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "insitu/config.hpp"
#include "seismic/config_toml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  const std::string text = fuzz::as_string(data, size);
  static const std::vector<std::string> seismic_sections{"grid",   "time",     "medium",   "boundary",
                                                         "attenuation", "source", "receiver", "receiver_line"};
  try {
    std::string seismic_text;
    insitu::SessionConfig cfg = insitu::parse_combined_config(text, "fuzz.toml", seismic_sections, seismic_text);
    cfg.validate();
  } catch (const Error&) {
  }
  try {
    seismic::RunConfig rc = seismic::parse_run_config(text, "fuzz.toml", "/nonexistent");
    rc.solver.validate();
  } catch (const Error&) {
  }
  return 0;
}
