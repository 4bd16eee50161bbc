#pragma once
// The standard scene of the renderer benchmarks (render_bench, inside_bench): one definition, so their
// numbers compare. 256x512x160 float32 p and s fields, two sources each; P fronts travel faster than
// S fronts, so their shells are larger. Sparse: about 20 % of the samples are marched.
#include <vector>

#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"

namespace panoptes::bench {

/// The two wave fields and their prepared copies (macro-cells, corner copies).
struct StandardScene {
  render::GridGeometry grid{{256, 512, 160}, {0, 0, 0}, {1, 1, 1}};
  std::vector<float> p, s;
  std::vector<render::PreparedField> fields;
  StandardScene() {
    const render::WaveFront pf[] = {{{128, 180, 90}, 150, 4, 1.0}, {{90, 380, 60}, 70, 4, 0.8}};
    const render::WaveFront sf[] = {{{128, 180, 90}, 87, 3, 1.0}, {{90, 380, 60}, 40, 3, 0.9}};
    p = render::wave_field(grid, pf);
    s = render::wave_field(grid, sf);
    fields = {render::PreparedField(render::FieldView::whole(grid, p.data())),
              render::PreparedField(render::FieldView::whole(grid, s.data()))};
  }
};

/// The scene, built once per process (it takes seconds).
inline const StandardScene& standard_scene() {
  static const StandardScene sc;
  return sc;
}

}  // namespace panoptes::bench
