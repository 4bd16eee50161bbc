#pragma once
// Where a strided 3-D array reaches in memory, every product and sum checked. A bounds check that
// multiplies extents by strides in plain 64-bit arithmetic wraps on huge strides (LLONG_MAX/7 + 1, 2^62)
// back into the buffer: the check passes and the reads land elsewhere (a crash, or plane 0 for every z).
// Every bounds check of field views (C API, C++ FieldInput, Python) goes through this.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

namespace panoptes {

/// The lowest and highest element offsets an array reaches, relative to the element `data` points at.
struct StridedReach {
  std::int64_t lo = 0, hi = 0;
};

/// The reach of an array of `extent` points per dimension at `stride` elements per dimension, relative
/// to the element of index `origin` (0 ≤ origin[d] < extent[d], or 0 when the extent is 0). nullopt when
/// any offset, or any offset times `element_bytes`, does not fit in 64 bits (the array cannot be
/// addressed). Dimensions with at most one point reach nothing, whatever their stride.
inline std::optional<StridedReach> strided_reach(const std::array<std::int64_t, 3>& extent,
                                                 const std::array<std::int64_t, 3>& stride, std::int64_t element_bytes,
                                                 const std::array<std::int64_t, 3>& origin = {0, 0, 0}) {
  std::int64_t lo = 0, hi = 0, shift = 0;  // relative to index (0, 0, 0)
  for (int d = 0; d < 3; ++d) {
    std::int64_t span = 0, at = 0;
    if (__builtin_mul_overflow(std::max<std::int64_t>(extent[d] - 1, 0), stride[d], &span)) return std::nullopt;
    if (__builtin_add_overflow(span > 0 ? hi : lo, span, span > 0 ? &hi : &lo)) return std::nullopt;
    if (__builtin_mul_overflow(origin[d], stride[d], &at) || __builtin_add_overflow(shift, at, &shift)) return std::nullopt;
  }
  StridedReach r;
  std::int64_t bytes = 0;
  if (__builtin_sub_overflow(lo, shift, &r.lo) || __builtin_sub_overflow(hi, shift, &r.hi)) return std::nullopt;
  for (std::int64_t v : {lo, hi, shift, r.lo, r.hi})
    if (__builtin_mul_overflow(v, element_bytes, &bytes)) return std::nullopt;
  return r;
}

}  // namespace panoptes
