#include "render/compositing_kernels.hpp"

namespace panoptes::render::march {

std::vector<MixEntry> mix_entries(const TransferLut& lut) {
  std::vector<MixEntry> m(std::size_t(lut.bins()));
  for (int b = 0; b < lut.bins(); ++b) {
    const LutEntry& e = lut.entry(b);
    m[std::size_t(b)] = {e.tau * e.r, e.tau * e.g, e.tau * e.b, e.tau, 1.0f - e.alpha};
  }
  return m;
}

std::vector<VolRow> vol_rows(const TransferLut& lut) {
  std::vector<VolRow> m(std::size_t(lut.bins()));
  for (int b = 0; b < lut.bins(); ++b) {
    const LutEntry& e = lut.entry(b);
    m[std::size_t(b)] = {e.pr, e.pg, e.pb, 1.0f - e.alpha};
  }
  return m;
}

}  // namespace panoptes::render::march
