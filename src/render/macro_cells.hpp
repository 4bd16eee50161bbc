#pragma once
// Min/max macro-cells of a field on a brick: the data structure behind empty-space skipping.
#include <utility>
#include <vector>

#include "render/corner_field.hpp"
#include "render/field_view.hpp"

namespace panoptes::render {

/// The brick's cells grouped into blocks of size³ cells ("macro-cells"), each with the minimum and
/// maximum of the field over its points PLUS a one-point margin on every side. The margin makes
/// skipping conservative even for samples that rounding places just outside a macro-cell, so
/// skipping never changes an image. Built once per field and snapshot, shared by all cameras.
class MacroCells {
 public:
  static constexpr int kDefaultSize = 8;
  MacroCells() = default;
  /// Builds the min/max table (OpenMP-parallel over macro-cell slabs). `size` ≥ 1 cells per side.
  explicit MacroCells(const FieldView& field, int size = kDefaultSize);

  int size() const { return size_; }
  const Index3& counts() const { return counts_; }
  int total() const { return counts_[0] * counts_[1] * counts_[2]; }
  int linear(int mx, int my, int mz) const { return mx + counts_[0] * (my + counts_[1] * mz); }
  float min(int m) const { return min_[m]; }
  float max(int m) const { return max_[m]; }

 private:
  int size_ = kDefaultSize;
  Index3 counts_{0, 0, 0};
  std::vector<float> min_, max_;
};

/// Whether PreparedField builds the march's 16-bit corner copy of the field (CornerField).
enum class FieldCopy { corners16, none };

/// A field view together with its macro-cells and (by default) its 16-bit corner copy: what the
/// renderer takes. Build one per field per snapshot (the passes read the brick once) and reuse it
/// for every camera. Volume tasks classify samples from the corner copy (images within PSNR ≥ 45 dB
/// of the float field's, see docs/rendering.md); isosurfaces, slices and shading read the float field.
struct PreparedField {
  FieldView view;
  MacroCells cells;
  CornerField corners;

  PreparedField() = default;
  /// Validates the view and builds its macro-cells and, with FieldCopy::corners16, the corner copy.
  /// `keep`: the values the tasks tell apart (prepare_fields(); the default keeps the whole range).
  explicit PreparedField(const FieldView& v, int macro_cell_size = MacroCells::kDefaultSize,
                         FieldCopy copy = FieldCopy::corners16, QuantizationRange keep = {})
      : view((v.validate(), v)), cells(v, macro_cell_size) {
    if (copy == FieldCopy::corners16) corners = CornerField(v, keep);
  }
  /// With a corner copy built elsewhere (e.g. one half of CornerField::joint()).
  PreparedField(const FieldView& v, CornerField copy, int macro_cell_size = MacroCells::kDefaultSize)
      : view((v.validate(), v)), cells(v, macro_cell_size), corners(std::move(copy)) {}
};

}  // namespace panoptes::render
