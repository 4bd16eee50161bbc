// Every optimisation of the march keeps images within PSNR >= 45 dB of the plain reference path
// (render/reference_renderer.hpp: the sampling and compositing rules written directly, as the
// renderer computed them before the optimisations of issue 10) on a small dense scene.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "camera/framing.hpp"
#include "camera/rig_spec.hpp"
#include "core/image.hpp"
#include "render/reference_renderer.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

struct DenseScene {
  GridGeometry grid{{40, 80, 26}, {0, 0, 0}, {1, 1, 1}};
  DenseWaveScene waves = dense_wave_scene(grid);
  std::vector<FieldView> views{FieldView::whole(grid, waves.p.data()), FieldView::whole(grid, waves.s.data())};
  // The paper's three tasks with windows relative to the 99.9th percentile of |v|, as the session sets them.
  std::vector<TaskSpec> tasks;
  DenseScene() {
    const double rp = abs_percentile(views[0], 0.999), rs = abs_percentile(views[1], 0.999);
    const auto w = ValueWindow::relative_to(0, 1.0);
    tasks = {TaskSpec::volume(0, TransferFunction::preset("p-wave"), w, rp),
             TaskSpec::volume(1, TransferFunction::preset("s-wave"), w, rs),
             TaskSpec::volume2(0, TransferFunction::preset("p-wave"), w, 1, TransferFunction::preset("s-wave"), w, rp, rs)};
  }
};

}  // namespace

TEST(Quality, DenseSceneMatchesTheReferencePathWithin45dB) {
  const DenseScene sc;
  // The scene is dense: most points are above the presets' 10 % opacity threshold.
  std::size_t above = 0;
  const float thr = float(0.1 * abs_percentile(sc.views[0], 0.999));
  for (float v : sc.waves.p) above += std::abs(v) > thr;
  EXPECT_GT(double(above) / double(sc.waves.p.size()), 0.5);

  const camera::Domain domain{sc.grid.domain_lo(), sc.grid.domain_hi() - sc.grid.domain_lo()};
  const camera::Rig rig = camera::make_rig("yinyang", domain);
  std::vector<PreparedField> fields{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  double worst = 99;
  for (int c : {0, 37, 71, 118}) {
    const camera::Camera cam = rig.camera(c, 96, 92);
    std::vector<PartialImage> fast(sc.tasks.size()), ref(sc.tasks.size());
    render_brick(cam, fields, sc.tasks, fast);
    render_reference(cam, sc.views, sc.tasks, ref);
    for (std::size_t t = 0; t < sc.tasks.size(); ++t) {
      const Image a = finish_image(fast[t], cam, sc.grid), b = finish_image(ref[t], cam, sc.grid);
      const double p = psnr(a, b);
      worst = std::min(worst, p);
      EXPECT_GE(p, 45.0) << "camera " << c << " task " << t;
      // And the images are not empty: the test would pass trivially on two blank frames.
      double alpha = 0;
      for (std::size_t i = 3; i < ref[t].rgba.size(); i += 4) alpha += ref[t].rgba[i];
      EXPECT_GT(alpha / double(ref[t].rgba.size() / 4), 0.05) << "camera " << c << " task " << t;
    }
  }
  RecordProperty("worst_psnr_db", std::to_string(worst));
  std::printf("worst PSNR against the reference path: %.1f dB\n", worst);
}
