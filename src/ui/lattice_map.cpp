#include "ui/lattice_map.hpp"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace panoptes::ui {
namespace {
constexpr double kAzimuth = -60 * M_PI / 180, kElevation = 30 * M_PI / 180;  // from the south-west, above
}

void LatticeMap::set_scene(std::vector<Vec3> positions, Vec3 box_lo, Vec3 box_hi) {
  positions_ = std::move(positions);
  for (int a = 0; a < 3; ++a) {
    lo_[a] = std::min(box_lo[a], box_hi[a]);
    hi_[a] = std::max(box_lo[a], box_hi[a]);
  }
  for (const Vec3& p : positions_)
    for (int a = 0; a < 3; ++a) lo_[a] = std::min(lo_[a], p[a]), hi_[a] = std::max(hi_[a], p[a]);
  centre_ = (lo_ + hi_) * 0.5;
  const double r = 0.5 * norm(hi_ - lo_);
  scale_ = r > 0 ? 1 / r : 1;
}

MapPoint LatticeMap::project(const Vec3& p) const {
  return project_to_map((p - centre_) * scale_, kAzimuth, kElevation);
}

int LatticeMap::draw(int current, const std::vector<int>& neighbours, const Vec3& view, float size, double half_fov_deg) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("##latticemap", ImVec2(size, size));
  const bool clicked = ImGui::IsItemClicked(ImGuiMouseButton_Left);
  const bool hovered = ImGui::IsItemHovered();
  const float radius = size * 0.46f;
  const ImVec2 c(p0.x + size / 2, p0.y + size / 2);
  auto to_screen = [&](const Vec3& p) {
    const MapPoint m = project(p);
    return ImVec2(c.x + float(m.x * radius), c.y + float(m.y * radius));
  };
  dl->AddRectFilled(p0, ImVec2(p0.x + size, p0.y + size), IM_COL32(20, 28, 40, 200));
  // The domain box: 12 edges.
  for (int a = 0; a < 3; ++a)
    for (int s = 0; s < 4; ++s) {
      Vec3 u = lo_, v = lo_;
      const int b = (a + 1) % 3, d = (a + 2) % 3;
      u[b] = v[b] = (s & 1) ? hi_[b] : lo_[b];
      u[d] = v[d] = (s & 2) ? hi_[d] : lo_[d];
      v[a] = hi_[a];
      dl->AddLine(to_screen(u), to_screen(v), IM_COL32(90, 110, 140, 255), 1.0f);
    }
  // Orientation marks at the south-west bottom corner: north (+y) and the sky (+z), a third of the box.
  {
    const double len = 0.3 / scale_;
    const ImVec2 o = to_screen(lo_);
    const ImVec2 n = to_screen(lo_ + Vec3{0, len, 0}), up = to_screen(lo_ + Vec3{0, 0, len});
    dl->AddLine(o, n, IM_COL32(235, 90, 80, 255), 2.0f);
    dl->AddText(ImVec2(n.x + 2, n.y - 7), IM_COL32(235, 90, 80, 255), "N");
    dl->AddLine(o, up, IM_COL32(120, 180, 255, 255), 2.0f);
    dl->AddText(ImVec2(up.x + 3, up.y - 10), IM_COL32(120, 180, 255, 255), "sky");
  }
  // Cameras back to front, so nearer dots cover farther ones.
  std::vector<int> order(positions_.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int i, int j) { return project(positions_[std::size_t(i)]).depth < project(positions_[std::size_t(j)]).depth; });
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  int hit = -1;
  float hit_d2 = 8.f * 8.f;
  for (int i : order) {
    const ImVec2 s = to_screen(positions_[std::size_t(i)]);
    const bool nb = std::find(neighbours.begin(), neighbours.end(), i) != neighbours.end();
    dl->AddCircleFilled(s, nb ? 3.2f : 2.2f, nb ? IM_COL32(80, 220, 230, 255) : IM_COL32(170, 190, 220, 220), 8);
    if (hovered) {
      const float dx = s.x - mouse.x, dy = s.y - mouse.y;
      if (dx * dx + dy * dy < hit_d2) hit_d2 = dx * dx + dy * dy, hit = i;
    }
  }
  if (current >= 0 && current < int(positions_.size())) {
    const Vec3& p = positions_[std::size_t(current)];
    const ImVec2 s = to_screen(p);
    // The view: a cone as wide as the field of view (turned about the sky axis), a third of the box's
    // half diagonal long, and its axis.
    const Vec3 f = normalize(view);
    const double len = 0.35 / scale_;
    Vec3 side = cross(f, Vec3{0, 0, 1});
    if (half_fov_deg > 0 && norm(side) > 1e-6) {
      side = normalize(side);
      const double a = half_fov_deg * M_PI / 180;
      const ImVec2 l = to_screen(p + (f * std::cos(a) - side * std::sin(a)) * len);
      const ImVec2 r = to_screen(p + (f * std::cos(a) + side * std::sin(a)) * len);
      dl->AddTriangleFilled(s, l, r, IM_COL32(255, 210, 40, 70));
      dl->AddLine(s, l, IM_COL32(255, 210, 40, 200), 1.0f);
      dl->AddLine(s, r, IM_COL32(255, 210, 40, 200), 1.0f);
    }
    dl->AddLine(s, to_screen(p + f * len), IM_COL32(255, 210, 40, 255), 2.0f);
    dl->AddCircleFilled(s, 4.5f, IM_COL32(255, 210, 40, 255), 12);
  }
  if (hit >= 0) {
    dl->AddCircle(to_screen(positions_[std::size_t(hit)]), 6.f, IM_COL32(255, 255, 255, 255), 12, 1.5f);
    ImGui::SetTooltip("camera %d (click to jump)", hit);
  }
  return clicked ? hit : -1;
}

}  // namespace panoptes::ui
