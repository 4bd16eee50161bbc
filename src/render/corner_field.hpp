#pragma once
// The march's per-snapshot copy of a field: every cell's eight corner values, quantized to 16 bits
// and stored together, so one trilinear sample is one 16-byte load instead of eight gathered floats.
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

#include "render/field_view.hpp"

namespace panoptes::render {

/// Allocator for the march's large per-snapshot copies: 2 MiB-aligned blocks advised as transparent
/// huge pages (madvise(MADV_HUGEPAGE), before the first touch), since the march reads them at
/// scattered cells and 4 KiB pages would cost a TLB miss on most of its loads.
void* allocate_huge(std::size_t bytes);
void deallocate_huge(void* p) noexcept;
template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_huge(n * sizeof(T))); }
  void deallocate(T* p, std::size_t) noexcept { deallocate_huge(p); }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

/// For every cell whose lower corner (i, j, k) lies in [points.lo, points.hi − 2] of a view, the
/// field at its 8 corners in the order (0,0,0), (1,0,0), (0,1,0), (1,1,0), (0,0,1), (1,0,1),
/// (0,1,1), (1,1,1), as q ∈ [0, 65535] with value = offset + scale·q (rounded to nearest: the error
/// is at most scale / 2 = (max − min) / 131070 of the view's value range). 16 bytes per cell: four
/// times the float32 field, paid once per snapshot and shared by every camera and task.
class CornerField {
 public:
  CornerField() = default;
  /// Builds the copy (OpenMP-parallel). Views with more than 2^31 − 1 cells get an empty copy (the
  /// renderer then reads the float field).
  explicit CornerField(const FieldView& view);

  bool empty() const { return q_.empty(); }
  /// 8 values per cell, cells x fastest over counts().
  const std::uint16_t* data() const { return q_.data(); }
  /// Global index of the first cell's lower corner (= the view's points.lo).
  const Index3& lo() const { return lo_; }
  /// Cells per axis.
  const Index3& counts() const { return counts_; }
  float offset() const { return offset_; }
  float scale() const { return scale_; }
  std::size_t bytes() const { return q_.size() * sizeof(std::uint16_t); }

 private:
  std::vector<std::uint16_t, HugePageAllocator<std::uint16_t>> q_;
  Index3 lo_{0, 0, 0}, counts_{0, 0, 0};
  float offset_ = 0, scale_ = 0;
};

}  // namespace panoptes::render
