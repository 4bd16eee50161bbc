// Looking around in 360° frames: the cut-out of a rendered equirectangular frame equals the perspective
// render of a turned camera, and the look/walk helpers follow the lattice.
#include "player/look.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "camera/camera.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "store/synthetic.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

double frame_psnr(const Image& a, const Image& b) {
  double se = 0;
  std::size_t n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c, ++n) {
        const double d = double(a.at(x, y)[c]) - b.at(x, y)[c];
        se += d * d;
      }
  return se == 0 ? 99 : 10 * std::log10(255.0 * 255.0 / (se / double(n)));
}

Image render_image(const camera::Camera& cam, const std::vector<FieldView>& views, const std::vector<TaskSpec>& tasks,
             const GridGeometry& grid) {
  std::vector<PreparedField> fields;
  for (const FieldView& f : views) fields.emplace_back(f);
  std::vector<PartialImage> out(1);
  render_brick(cam, fields, tasks, out);
  return finish_image(out[0], cam, grid, {0.1f, 0.1f, 0.15f}, OutlineStyle{false});
}

}  // namespace

TEST(LookAround, NinetyDegreeYawCutoutEqualsTheTurnedPerspectiveCamera) {
  const GridGeometry grid{{41, 37, 33}, {-20, -21.6, -12.8}, {1.0, 1.2, 0.8}};
  const WaveFront fronts[] = {{{-4, 3, 1}, 14, 2.5, 1.0}, {{6, -5, -2}, 8, 2, -0.8}};
  const std::vector<float> p = wave_field(grid, fronts);
  const std::vector<FieldView> views{FieldView::whole(grid, p.data())};
  const std::vector<TaskSpec> tasks{
      TaskSpec::volume(0, TransferFunction::preset("diverging", 3), ValueWindow::absolute(-1, 1))};
  const Vec3 eye{-2, 1, 0.5};
  // Camera looking +y with +z up: its right is +x. Yaw +90° looks along +x.
  const camera::Camera equi(eye, eye + Vec3{0, 5, 0}, {0, 0, 1}, 60, 1024, 512, camera::Projection::equirectangular);
  const Image pano = render_image(equi, views, tasks, grid);
  store::CameraEntry entry;
  entry.position = eye, entry.look_at = eye + Vec3{0, 5, 0}, entry.up = {0, 0, 1};
  for (const player::Look look : {player::Look{90, 0, 60}, player::Look{90, 20, 60}, player::Look{-135, -10, 70}}) {
    const player::ViewBasis turned = player::look_basis(player::camera_basis(entry), look);
    const camera::Camera persp(eye, eye + turned.forward, turned.up, look.fov_deg, 96, 96);
    const Image want = render_image(persp, views, tasks, grid);
    Image got(96, 96, 4);
    player::perspective_cutout(pano, player::camera_basis(entry), look, got);
    EXPECT_GE(frame_psnr(got, want), 35.0) << "yaw " << look.yaw_deg << " pitch " << look.pitch_deg;
  }
  if (true) {
    // The 90° yaw looks along the camera's right vector.
    const player::ViewBasis b = player::look_basis(player::camera_basis(entry), {90, 0, 60});
    EXPECT_NEAR(b.forward.x, 1, 1e-12);
  }
}

TEST(LookAround, WalkingFollowsTheViewOnALattice) {
  store::SyntheticOptions o;
  o.lattice = {4, 3, 2};
  o.frames = 1;
  const store::Manifest m = store::synthetic_manifest(o);
  ASSERT_EQ(m.camera_count(), 24);
  EXPECT_EQ(player::lattice_shape(m), (std::array<int, 3>{4, 3, 2}));
  EXPECT_EQ(player::lattice_node({4, 3, 2}, 1 + 4 * (2 + 3 * 1)), (std::array<int, 3>{1, 2, 1}));
  const int c = 1 + 4 * 1;  // node (1, 1, 0)
  using player::Walk;
  EXPECT_EQ(player::walk_target(m, c, {0, 0, 90}, Walk::forward), 1 + 4 * 2);   // facing +y
  EXPECT_EQ(player::walk_target(m, c, {90, 0, 90}, Walk::forward), 2 + 4 * 1);  // facing +x
  EXPECT_EQ(player::walk_target(m, c, {90, 0, 90}, Walk::left), 1 + 4 * 2);     // left of +x is +y
  EXPECT_EQ(player::walk_target(m, c, {180, 0, 90}, Walk::forward), 1);         // facing −y
  EXPECT_EQ(player::walk_target(m, c, {-90, 30, 90}, Walk::forward), 0 + 4 * 1); // −x, looking a little up
  EXPECT_EQ(player::walk_target(m, c, {0, 0, 90}, Walk::up), c + 12);
  EXPECT_EQ(player::walk_target(m, c, {0, 0, 90}, Walk::down), -1);  // bottom layer
  const int tie = player::walk_target(m, c, {45, 0, 90}, Walk::forward);  // a tie goes to one of the two, not nowhere
  EXPECT_TRUE(tie == 2 + 4 * 1 || tie == 1 + 4 * 2) << tie;
  EXPECT_FALSE(player::is_equirectangular(m));
  o.projection = "equirectangular";
  EXPECT_TRUE(player::is_equirectangular(store::synthetic_manifest(o)));
  // look_towards inverts look_basis.
  const player::ViewBasis cam = player::camera_basis(m.cameras[0]);
  const player::Look l{-70, 25, 50};
  const player::Look back = player::look_towards(cam, player::look_basis(cam, l).forward, 50);
  EXPECT_NEAR(back.yaw_deg, -70, 1e-9);
  EXPECT_NEAR(back.pitch_deg, 25, 1e-9);
}
