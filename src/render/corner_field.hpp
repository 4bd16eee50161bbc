#pragma once
// The march's per-snapshot copy of a field: every cell's eight corner values, quantized to 16 bits
// and stored together, so one trilinear sample is one 16-byte load instead of eight gathered floats.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include "render/field_view.hpp"

namespace panoptes::render {

/// Allocator for the march's large per-snapshot copies: 2 MiB-aligned blocks advised as transparent
/// huge pages (madvise(MADV_HUGEPAGE), before the first touch), since the march reads them at
/// scattered cells and 4 KiB pages would cost a TLB miss on most of its loads. The contents are not
/// initialized. Blocks of 2 MiB and more are kept when freed (at most kIdleHugeBlocks, newest kept)
/// and handed out again for the same rounded size: every snapshot frees its copies and asks for
/// blocks of the same sizes, and fresh memory costs a page fault and the kernel's zeroing of every
/// page on first touch (the paper's 670 MB corner copy: ~10 % of a dense snapshot's CPU).
void* allocate_huge(std::size_t bytes);
void deallocate_huge(void* p) noexcept;
/// The freed large blocks allocate_huge() keeps at most.
inline constexpr std::size_t kIdleHugeBlocks = 4;
/// Returns the kept blocks to the system (a session's end: nothing will ask for them again).
void release_idle_huge_blocks() noexcept;
/// Bytes of the blocks kept for reuse now.
std::size_t idle_huge_bytes() noexcept;
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

/// The values a march must tell apart in a corner copy: beyond [lo, hi] every task reading the copy
/// shows the same thing (its transfer function is constant past its window), so the copy clamps the
/// field to it and spends its 65,536 levels inside (prepare_fields() derives it from the tasks). The
/// default keeps the whole value range.
struct QuantizationRange {
  float lo = -std::numeric_limits<float>::infinity();
  float hi = std::numeric_limits<float>::infinity();
};

/// For every cell whose lower corner (i, j, k) lies in [points.lo, points.hi − 2] of a view, the
/// field at its 8 corners in the order (0,0,0), (1,0,0), (0,1,0), (1,1,0), (0,0,1), (1,0,1),
/// (0,1,1), (1,1,1), as q ∈ [0, 65535] with value = offset + scale·q (rounded to nearest: the error
/// is at most scale / 2 = (max − min) / 131070 of the view's value range, clamped to the
/// QuantizationRange). Without the clamp a source's near field 26,000x a task's fixed window left a
/// step of 0.8x the window: zero read back as 0.4x it, and the paper's p movies showed an orange box
/// where the solver's field was exactly zero. 16 bytes per cell: four
/// times the float32 field, paid once per snapshot and shared by every camera and task.
///
/// Two fields of one point range that a march reads together (the paper's p and s) may share one
/// buffer (joint()): cell records of 32 bytes, the first field's 8 values then the second's, so a
/// sample of both is one cache line instead of two (docs/rendering.md, Round 9). Values and
/// quantization are those of two separate copies.
class CornerField {
 public:
  CornerField() = default;
  /// Builds the copy (OpenMP-parallel). Views with more than 2^31 − 1 cells get an empty copy (the
  /// renderer then reads the float field).
  explicit CornerField(const FieldView& view, QuantizationRange keep = {});
  /// The copies of two views with the same point range in one interleaved buffer: first.data() and
  /// second.data() point 8 values apart, record() = 16. Throws panoptes::Error when the point
  /// ranges differ.
  static std::pair<CornerField, CornerField> joint(const FieldView& a, const FieldView& b, QuantizationRange keep_a = {},
                                                   QuantizationRange keep_b = {});

  bool empty() const { return data_ == nullptr; }
  /// This field's 8 values of cell c start at data() + record()·c (cells x fastest over counts()).
  const std::uint16_t* data() const { return data_; }
  /// Values from one cell's record to the next: 8, or 16 in a joint copy.
  int record() const { return record_; }
  /// Global index of the first cell's lower corner (= the view's points.lo).
  const Index3& lo() const { return lo_; }
  /// Cells per axis.
  const Index3& counts() const { return counts_; }
  float offset() const { return offset_; }
  float scale() const { return scale_; }
  /// This field's share of the buffer: 16 bytes per cell (a joint buffer is the sum of both).
  std::size_t bytes() const {
    return data_ ? std::size_t(16) * std::size_t(counts_[0]) * std::size_t(counts_[1]) * std::size_t(counts_[2]) : 0;
  }

 private:
  // Checks the view, sets lo_ and counts_; false when the copy would have too many cells.
  bool shape(const FieldView& view);
  // A scratch array from allocate_huge(), not initialized (every element is written before it is read).
  using Points = std::unique_ptr<std::uint16_t[], void (*)(std::uint16_t*)>;
  // The view's points quantized (sets offset_ and scale_), x fastest.
  Points quantize(const FieldView& view, QuantizationRange keep);
  // Allocates the buffer (huge pages, not zeroed: every value is written) and writes the records
  // of nf fields (1 or 2) from their quantized points, one pass over the buffer.
  static std::shared_ptr<std::uint16_t> write_records(const std::uint16_t* const* pq, int nf, const FieldView& view,
                                                      const Index3& counts);

  std::shared_ptr<std::uint16_t> q_;
  const std::uint16_t* data_ = nullptr;
  int record_ = 8;
  Index3 lo_{0, 0, 0}, counts_{0, 0, 0};
  float offset_ = 0, scale_ = 0;
};

}  // namespace panoptes::render
