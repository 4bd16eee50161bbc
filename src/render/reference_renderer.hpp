#pragma once
// A plain reference ray caster for volume and isosurface tasks: the renderer's sampling and compositing rules
// written as directly as possible (double-precision positions, one clamped trilinear interpolation
// and one LUT lookup per sample, no skipping, no blocks, no field copies). It is the yardstick for
// the optimized march: tests and benchmarks measure PSNR of render_brick() against it.
#include <span>

#include "render/renderer.hpp"

namespace panoptes::render {

/// Renders volume tasks (one or two fields) and isosurfaces (first crossing, the pre-issue-10
/// shading of iso_shading.hpp) of one camera over whole-grid fields (brick = whole
/// grid) into `out` (one PartialImage per task), with the sample positions, partial last sample,
/// opacity correction and early termination of render_brick(). Slow (scalar): for small images or
/// a few cameras. Throws panoptes::Error for other task kinds, for fields that are not whole-grid
/// views, or when out.size() != tasks.size().
void render_reference(const camera::Camera& cam, std::span<const FieldView> fields, std::span<const TaskSpec> tasks,
                      std::span<PartialImage> out, const RenderOptions& options = {});

}  // namespace panoptes::render
