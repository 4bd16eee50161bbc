#include "ui/look_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace panoptes::ui {

namespace {

// Clips a polygon (with unwrapped u) to u <= limit (keep_below) or u >= limit, appending the result.
int clip(const MeshVertex* in, int n, float limit, bool keep_below, MeshVertex* out) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const MeshVertex& a = in[i];
    const MeshVertex& b = in[(i + 1) % n];
    const bool ain = keep_below ? a.u <= limit : a.u >= limit;
    const bool bin = keep_below ? b.u <= limit : b.u >= limit;
    if (ain) out[m++] = a;
    if (ain != bin) {
      const float t = (limit - a.u) / (b.u - a.u);
      out[m++] = {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, limit, a.v + (b.v - a.v) * t};
    }
  }
  return m;
}

void emit_fan(const MeshVertex* p, int n, float shift, std::vector<MeshVertex>& out) {
  for (int i = 1; i + 1 < n; ++i)
    for (const MeshVertex* q : {&p[0], &p[i], &p[i + 1]}) out.push_back({q->x, q->y, q->u + shift, q->v});
}

void emit_triangle(MeshVertex a, MeshVertex b, MeshVertex c, std::vector<MeshVertex>& out) {
  // Unwrap: a triangle whose u values span more than half the texture straddles the seam.
  const float lo = std::min({a.u, b.u, c.u}), hi = std::max({a.u, b.u, c.u});
  if (hi - lo <= 0.5f) {
    out.push_back(a), out.push_back(b), out.push_back(c);
    return;
  }
  for (MeshVertex* p : {&a, &b, &c})
    if (p->u < 0.5f) p->u += 1.0f;
  const std::array<MeshVertex, 3> tri{a, b, c};
  std::array<MeshVertex, 6> piece{};
  int n = clip(tri.data(), 3, 1.0f, true, piece.data());  // the part left of the seam, u in [.., 1]
  emit_fan(piece.data(), n, 0.0f, out);
  n = clip(tri.data(), 3, 1.0f, false, piece.data());     // the part beyond it, shifted back to [0, ..]
  emit_fan(piece.data(), n, -1.0f, out);
}

}  // namespace

void build_look_mesh(const player::ViewBasis& cam, const player::Look& look, float x0, float y0, float w, float h,
                     std::vector<MeshVertex>& triangles, int cells_x, int cells_y) {
  triangles.clear();
  if (!(w > 0 && h > 0) || cells_x < 1 || cells_y < 1) return;
  const player::ViewBasis v = player::look_basis(cam, look);
  const double tan_half = std::tan(look.fov_deg * std::numbers::pi / 360.0), aspect = double(w) / h;
  std::vector<MeshVertex> grid(std::size_t(cells_x + 1) * (cells_y + 1));
  for (int j = 0; j <= cells_y; ++j)
    for (int i = 0; i <= cells_x; ++i) {
      const double fx = double(i) / cells_x, fy = double(j) / cells_y;
      const double sx = (2 * fx - 1) * tan_half * aspect, sy = (1 - 2 * fy) * tan_half;
      const Vec3 d = v.forward + v.right * sx + v.up * sy;
      const double cx = dot(d, cam.right), cy = dot(d, cam.up), cz = dot(d, cam.forward);
      const double lon = std::atan2(cx, cz), lat = std::atan2(cy, std::hypot(cx, cz));
      grid[std::size_t(j) * (cells_x + 1) + i] = {float(x0 + fx * w), float(y0 + fy * h),
                                                  float(lon / (2 * std::numbers::pi) + 0.5),
                                                  float(0.5 - lat / std::numbers::pi)};
    }
  triangles.reserve(std::size_t(cells_x) * cells_y * 6 + 64);
  for (int j = 0; j < cells_y; ++j)
    for (int i = 0; i < cells_x; ++i) {
      const MeshVertex& a = grid[std::size_t(j) * (cells_x + 1) + i];
      const MeshVertex& b = grid[std::size_t(j) * (cells_x + 1) + i + 1];
      const MeshVertex& c = grid[std::size_t(j + 1) * (cells_x + 1) + i];
      const MeshVertex& d = grid[std::size_t(j + 1) * (cells_x + 1) + i + 1];
      emit_triangle(a, b, c, triangles);
      emit_triangle(b, d, c, triangles);
    }
}

double look_mesh_error(const player::ViewBasis& cam, const player::Look& look, float x0, float y0, float w, float h,
                       const std::vector<MeshVertex>& tris, int source_width) {
  const player::ViewBasis v = player::look_basis(cam, look);
  const double tan_half = std::tan(look.fov_deg * std::numbers::pi / 360.0), aspect = double(w) / h;
  double worst = 0;
  for (std::size_t k = 0; k + 2 < tris.size(); k += 3) {
    const MeshVertex &a = tris[k], &b = tris[k + 1], &c = tris[k + 2];
    const double fx = ((a.x + b.x + c.x) / 3.0 - x0) / w, fy = ((a.y + b.y + c.y) / 3.0 - y0) / h;
    const Vec3 d = v.forward + v.right * ((2 * fx - 1) * tan_half * aspect) + v.up * ((1 - 2 * fy) * tan_half);
    const double cx = dot(d, cam.right), cy = dot(d, cam.up), cz = dot(d, cam.forward);
    const double u = std::atan2(cx, cz) / (2 * std::numbers::pi) + 0.5;
    const double t = 0.5 - std::atan2(cy, std::hypot(cx, cz)) / std::numbers::pi;
    double du = (a.u + b.u + c.u) / 3.0 - u;
    du -= std::round(du);  // u wraps at the seam
    worst = std::max({worst, std::abs(du) * source_width, std::abs((a.v + b.v + c.v) / 3.0 - t) * source_width / 2});
  }
  return worst;
}

int build_fitted_look_mesh(const player::ViewBasis& cam, const player::Look& look, float x0, float y0, float w, float h,
                           int source_width, std::vector<MeshVertex>& triangles, int* cells_y) {
  // Error (source pixels) ~ kCurvature * source_width * (cell angle in radians)^2 away from the poles.
  constexpr double kCurvature = 0.6, kMaxError = 0.5;
  constexpr int kMaxCells = 128;
  const double fov_y = std::clamp(look.fov_deg, 1.0, 179.0) * std::numbers::pi / 180.0;
  const double aspect = h > 0 ? double(w) / h : 1.0;
  const double fov_x = 2 * std::atan(std::tan(fov_y / 2) * aspect);
  const double per_radian = std::sqrt(kCurvature * std::max(source_width, 1) / kMaxError);
  int cx = std::clamp(int(std::ceil(fov_x * per_radian)), 8, kMaxCells);
  int cy = std::clamp(int(std::ceil(fov_y * per_radian)), 8, kMaxCells);
  for (;;) {
    build_look_mesh(cam, look, x0, y0, w, h, triangles, cx, cy);
    if ((cx >= kMaxCells && cy >= kMaxCells) || look_mesh_error(cam, look, x0, y0, w, h, triangles, source_width) <= kMaxError)
      break;
    cx = std::min(kMaxCells, cx + (cx + 1) / 2);
    cy = std::min(kMaxCells, cy + (cy + 1) / 2);
  }
  if (cells_y) *cells_y = cy;
  return cx;
}

}  // namespace panoptes::ui
