#pragma once
// Helpers shared by the render tests (not part of the library).
#include <algorithm>
#include <cstdlib>
#include <vector>

#include "render/renderer.hpp"

namespace panoptes::render::testing {

/// Renders `tasks` for the bricks `bricks` of the whole fields `whole` (each brick gets subviews
/// restricted to its ghosted point range), composites per pixel by depth and finishes the images.
inline std::vector<Image> render_bricked(const camera::Camera& cam, const std::vector<FieldView>& whole,
                                         const std::vector<TaskSpec>& tasks, const std::vector<Brick>& bricks,
                                         const RenderOptions& opt = {}, bool ordered = false,
                                         const OutlineStyle& outline = {false}) {
  std::vector<std::vector<PartialImage>> parts(bricks.size(), std::vector<PartialImage>(tasks.size()));
  for (std::size_t b = 0; b < bricks.size(); ++b) {
    std::vector<PreparedField> fields;
    for (const FieldView& f : whole) fields.emplace_back(f.subview(bricks[b]));
    render_brick(cam, fields, tasks, parts[b], opt);
  }
  std::vector<Image> images;
  const std::vector<int> order = visibility_order(cam, whole[0].grid, bricks);
  for (std::size_t t = 0; t < tasks.size(); ++t) {
    std::vector<const PartialImage*> ps;
    if (ordered)
      for (int b : order) ps.push_back(&parts[std::size_t(b)][t]);
    else
      for (auto& p : parts) ps.push_back(&p[t]);
    const PartialImage c = ordered ? composite_ordered(tasks[t].kind, ps) : composite(tasks[t].kind, ps);
    images.push_back(finish_image(c, cam, whole[0].grid, {0.1f, 0.1f, 0.15f}, outline));
  }
  return images;
}

/// Largest per-channel difference of two equally sized images.
inline int max_diff(const Image& a, const Image& b) {
  int m = 0;
  for (std::size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i)
    m = std::max(m, std::abs(int(a.pixels[i]) - int(b.pixels[i])));
  return a.pixels.size() == b.pixels.size() ? m : 256;
}

}  // namespace panoptes::render::testing
