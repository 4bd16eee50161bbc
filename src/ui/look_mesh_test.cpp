#include "ui/look_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace panoptes;

namespace {
// The exact texture coordinate of the ray through screen point (x, y) of a w x h view.
void exact_uv(const player::ViewBasis& cam, const player::Look& look, double x, double y, double w, double h, double& u,
              double& v) {
  const player::ViewBasis b = player::look_basis(cam, look);
  const double t = std::tan(look.fov_deg * std::numbers::pi / 360.0);
  const Vec3 d = b.forward + b.right * ((2 * x / w - 1) * t * w / h) + b.up * ((1 - 2 * y / h) * t);
  const double cx = dot(d, cam.right), cy = dot(d, cam.up), cz = dot(d, cam.forward);
  u = std::atan2(cx, cz) / (2 * std::numbers::pi) + 0.5;
  v = 0.5 - std::atan2(cy, std::hypot(cx, cz)) / std::numbers::pi;
}
}  // namespace

// Inside every triangle the linear texture coordinates stay within half a pixel of a 1920 x 960 frame
// of the exact mapping, also across the ±180° seam (looking backwards) and when looking steeply up.
TEST(LookMesh, InterpolatedTextureCoordinatesFollowTheExactMapping) {
  const player::ViewBasis cam;  // forward +y, right +x, up +z
  const float W = 800, H = 600;
  for (const player::Look look : {player::Look{0, 0, 90}, player::Look{180, 10, 90}, player::Look{-100, 40, 80},
                                  player::Look{170, -30, 40}}) {
    std::vector<ui::MeshVertex> tris;
    ui::build_look_mesh(cam, look, 0, 0, W, H, tris);
    ASSERT_EQ(tris.size() % 3, 0u);
    double worst = 0, area = 0;
    for (std::size_t k = 0; k < tris.size(); k += 3) {
      const ui::MeshVertex &a = tris[k], &b = tris[k + 1], &c = tris[k + 2];
      area += std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y)) / 2;
      for (int s = 0; s < 3; ++s) {
        EXPECT_GE(std::min({a.u, b.u, c.u}), -1e-6f);
        EXPECT_LE(std::max({a.u, b.u, c.u}), 1 + 1e-6f);
      }
      // The centroid: linear u, v against the exact ones (in source pixels; u wraps).
      const double x = (a.x + b.x + c.x) / 3, y = (a.y + b.y + c.y) / 3;
      const double lu = (a.u + b.u + c.u) / 3.0, lv = (a.v + b.v + c.v) / 3.0;
      double u, v;
      exact_uv(cam, look, x, y, W, H, u, v);
      double du = lu - u;
      du -= std::round(du);
      worst = std::max({worst, std::abs(du) * 1920, std::abs(lv - v) * 960});
    }
    EXPECT_NEAR(area, double(W) * H, 1.0) << "the triangles tile the view";
    EXPECT_LT(worst, 0.5) << "yaw " << look.yaw_deg << " pitch " << look.pitch_deg;
  }
}

// The grid fitted to the frame at hand keeps the interpolation within half a source pixel for small and
// large frames, windows and fields of view (views reaching within 10° of a pole are left out: at the pole
// longitude is undefined and no grid is exact; the fixed grid was no better there), with
// fewer triangles than the fixed 96 x 72 grid for the usual 768-pixel frames looking ahead (the software
// GL rasteriser pays per triangle).
TEST(LookMesh, FittedGridKeepsHalfASourcePixel) {
  const player::ViewBasis cam;
  struct Case {
    int source_w;
    float w, h;
    double fov;
  };
  for (const Case c : {Case{768, 1360, 680, 90}, Case{1920, 1360, 680, 90}, Case{768, 800, 600, 120},
                       Case{1920, 1920, 1080, 60}, Case{384, 640, 480, 20}}) {
    for (const player::Look look : {player::Look{0, 0, c.fov}, player::Look{180, 10, c.fov},
                                    player::Look{-100, 30, c.fov}, player::Look{170, -20, c.fov}}) {
      if (std::abs(look.pitch_deg) + c.fov / 2 > 80) continue;
      std::vector<ui::MeshVertex> tris;
      int cy = 0;
      const int cx = ui::build_fitted_look_mesh(cam, look, 0, 0, c.w, c.h, c.source_w, tris, &cy);
      if (c.source_w == 768 && c.fov == 90 && look.pitch_deg == 0)
        EXPECT_LT(cx * cy, 96 * 72 * 6 / 10) << "fewer triangles than the fixed grid";
      // The mesh's own error measure against the test's independent exact mapping.
      double worst = 0;
      for (std::size_t k = 0; k < tris.size(); k += 3) {
        const ui::MeshVertex &a = tris[k], &b = tris[k + 1], &d = tris[k + 2];
        double u, v;
        exact_uv(cam, look, (a.x + b.x + d.x) / 3, (a.y + b.y + d.y) / 3, c.w, c.h, u, v);
        double du = (a.u + b.u + d.u) / 3.0 - u;
        du -= std::round(du);
        worst = std::max({worst, std::abs(du) * c.source_w, std::abs((a.v + b.v + d.v) / 3.0 - v) * c.source_w / 2});
      }
      EXPECT_NEAR(worst, ui::look_mesh_error(cam, look, 0, 0, c.w, c.h, tris, c.source_w), 1e-3);
      EXPECT_LE(worst, 0.5 + 1e-6) << c.source_w << " px source, " << c.w << "x" << c.h << " view, fov " << c.fov
                                   << ", yaw " << look.yaw_deg << " pitch " << look.pitch_deg << " (" << cx << "x"
                                   << cy << " cells)";
    }
  }
}
