#include "render/macro_cells.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace panoptes::render {

MacroCells::MacroCells(const FieldView& f, int size) : size_(size) {
  f.validate();
  if (size < 1) throw Error("macro-cells: size " + std::to_string(size) + "; expected >= 1");
  const Brick& b = f.brick;
  for (int a = 0; a < 3; ++a) counts_[a] = (b.hi[a] - b.lo[a] + size - 1) / size;
  min_.assign(std::size_t(total()), 0.0f);
  max_.assign(std::size_t(total()), 0.0f);
  const PointRange& pr = f.points;
#pragma omp parallel for schedule(dynamic, 1)
  for (int mz = 0; mz < counts_[2]; ++mz)
    for (int my = 0; my < counts_[1]; ++my)
      for (int mx = 0; mx < counts_[0]; ++mx) {
        const int m[3] = {mx, my, mz};
        int lo[3], hi[3];  // inclusive point range with a one-point margin, clipped to the data
        for (int a = 0; a < 3; ++a) {
          const int c0 = b.lo[a] + m[a] * size;
          const int c1 = std::min(c0 + size, b.hi[a]);
          lo[a] = std::max(pr.lo[a], c0 - 1);
          hi[a] = std::min(pr.hi[a] - 1, c1 + 1);
        }
        float vmin = std::numeric_limits<float>::infinity(), vmax = -vmin;
        for (int k = lo[2]; k <= hi[2]; ++k)
          for (int j = lo[1]; j <= hi[1]; ++j) {
            const float* row = &f.data[std::int64_t(j - pr.lo[1]) * f.stride[1] + std::int64_t(k - pr.lo[2]) * f.stride[2]];
            for (int i = lo[0]; i <= hi[0]; ++i) {
              const float v = row[std::int64_t(i - pr.lo[0]) * f.stride[0]];
              vmin = std::min(vmin, v);
              vmax = std::max(vmax, v);
            }
          }
        const int id = linear(mx, my, mz);
        min_[std::size_t(id)] = vmin;
        max_[std::size_t(id)] = vmax;
      }
}

}  // namespace panoptes::render
