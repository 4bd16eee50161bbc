#pragma once
// The march's raw view of one field (FieldAcc: pointer, strides, clamp ranges, its corner copy) and
// scalar trilinear interpolation. Internal to the renderer: namespace march. Header-inline: every
// sample of the hot loops goes through it.
#include <algorithm>
#include <cstdint>

#include "render/field_view.hpp"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#define PANOPTES_RENDER_AVX2 1
#endif

namespace panoptes::render::march {

// Raw access to one field for the hot loop: global point (i, j, k) is data[off0 + i·sx + j·sy + k·sz].
struct FieldAcc {
  const float* data;
  std::int64_t sx, sy, sz, off0;
  int ilo[3], ihi[3];    // clamp range of a cell's lower corner: [points.lo, points.hi − 2]
  float plo[3], phi[3];  // clamp range of positions: [points.lo, points.hi − 1]
  // Every element offset from the point points.lo fits a signed 32-bit lane and strides are
  // non-negative: the vectorized interpolation may gather with 32-bit indices.
  bool gather32 = false;
  // The field's CornerField (nullptr without one): volume classification reads it; isosurfaces,
  // slices and shading read the float field.
  const std::uint16_t* corners = nullptr;
  std::int32_t ccx = 0, ccxy = 0;  // corner records per row / per slice
  std::int32_t crec = 8;           // uint16 per cell record (16: two fields interleaved)
  float qoff = 0, qscale = 0;      // value = qoff + qscale·q
};

inline FieldAcc make_acc(const FieldView& v) {
  FieldAcc a;
  a.data = v.data;
  a.sx = v.stride[0];
  a.sy = v.stride[1];
  a.sz = v.stride[2];
  a.off0 = -(v.points.lo[0] * a.sx + v.points.lo[1] * a.sy + v.points.lo[2] * a.sz);
  for (int k = 0; k < 3; ++k) {
    a.ilo[k] = v.points.lo[k];
    a.ihi[k] = std::max(v.points.lo[k], v.points.hi[k] - 2);
    a.plo[k] = float(v.points.lo[k]);
    a.phi[k] = float(v.points.hi[k] - 1);
  }
  std::int64_t max_off = 0;
  bool nonneg = true;
  for (int k = 0; k < 3; ++k) {
    nonneg = nonneg && v.stride[std::size_t(k)] >= 0;
    max_off += std::int64_t(v.points.hi[k] - v.points.lo[k] - 1) * v.stride[std::size_t(k)];
  }
  a.gather32 = nonneg && max_off + a.sx + a.sy + a.sz < (std::int64_t(1) << 31);
  return a;
}

// Trilinear interpolation at index-space position (x, y, z). With kClamp the cell index is clamped
// so float rounding at the data's faces can never read outside it; macro-cells that lie at least
// one cell inside the data on every side use kClamp = false (the march knows which, see
// MarchPlan::safe_lo/hi), which saves six min/max per field and sample. Both variants compute the same
// bits whenever the clamp would not change the index, so images do not depend on which one ran.
template <bool kClamp = true>
inline float interp(const FieldAcc& f, float x, float y, float z) {
  int i = int(x), j = int(y), k = int(z);
  if constexpr (kClamp) {
    i = std::min(std::max(i, f.ilo[0]), f.ihi[0]);
    j = std::min(std::max(j, f.ilo[1]), f.ihi[1]);
    k = std::min(std::max(k, f.ilo[2]), f.ihi[2]);
  }
  const float fx = x - float(i), fy = y - float(j), fz = z - float(k);
  const float* c = f.data + (f.off0 + i * f.sx + j * f.sy + k * f.sz);
  const std::int64_t sx = f.sx, sy = f.sy, sz = f.sz;
  const float c00 = c[0] + fx * (c[sx] - c[0]);
  const float c10 = c[sy] + fx * (c[sy + sx] - c[sy]);
  const float c01 = c[sz] + fx * (c[sz + sx] - c[sz]);
  const float c11 = c[sz + sy] + fx * (c[sz + sy + sx] - c[sz + sy]);
  const float c0 = c00 + fy * (c10 - c00);
  const float c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

// Interpolation at an arbitrary position (clamped into the data): off the hot path.
inline float interp_clamped(const FieldAcc& f, float x, float y, float z) {
  return interp(f, std::clamp(x, f.plo[0], f.phi[0]), std::clamp(y, f.plo[1], f.phi[1]),
                std::clamp(z, f.plo[2], f.phi[2]));
}
inline float interp_clamped(const FieldAcc& f, double x, double y, double z) {
  return interp_clamped(f, float(x), float(y), float(z));
}

}  // namespace panoptes::render::march
