#include "ui/minimap.hpp"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace panoptes::ui {
namespace {
constexpr double kElevation = 25 * M_PI / 180;  // look slightly from above: both poles stay readable
}

MapPoint project_to_map(const Vec3& d, double azimuth, double elevation) {
  const double ca = std::cos(azimuth), sa = std::sin(azimuth);
  const double ce = std::cos(elevation), se = std::sin(elevation);
  const Vec3 toward{ce * ca, ce * sa, se};  // from the centre towards the viewer
  const Vec3 right{-sa, ca, 0};
  const Vec3 up = cross(toward, right);
  return {dot(d, right), -dot(d, up), dot(d, toward)};
}

void MiniMap::set_cameras(std::vector<Vec3> directions, std::vector<int> shells) {
  dirs_ = std::move(directions);
  for (auto& d : dirs_) d = normalize(d);
  shells_ = std::move(shells);
  shells_.resize(dirs_.size(), 0);
  shell_count_ = 1;
  for (int s : shells_) shell_count_ = std::max(shell_count_, s + 1);
}

int MiniMap::draw(int current, const std::vector<int>& neighbours, float size) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("##minimap", ImVec2(size, size));
  const bool clicked = ImGui::IsItemClicked(ImGuiMouseButton_Left);
  const bool hovered = ImGui::IsItemHovered();
  const float radius = size * 0.46f;
  const ImVec2 c(p0.x + size / 2, p0.y + size / 2);

  if (current >= 0 && current < int(dirs_.size())) {
    const Vec3& d = dirs_[std::size_t(current)];
    const double target = (std::abs(d.x) + std::abs(d.y) > 1e-9) ? std::atan2(d.y, d.x) : azimuth_;
    if (!azimuth_set_) {
      azimuth_ = target;
      azimuth_set_ = true;
    }
    azimuth_ += 0.25 * std::remainder(target - azimuth_, 2 * M_PI);
  }
  auto to_screen = [&](const MapPoint& m, double r) {
    return ImVec2(c.x + float(m.x * r * radius), c.y + float(m.y * r * radius));
  };

  dl->AddCircleFilled(c, radius, IM_COL32(20, 28, 40, 200), 48);
  dl->AddCircle(c, radius, IM_COL32(140, 160, 190, 255), 48, 1.5f);
  // Equator and two meridians 45° either side of the view (the meridian through the view would be
  // seen edge-on), front halves solid, back halves faint.
  auto circle_point = [&](int line, double a) {
    if (line == 0) return Vec3{std::cos(a), std::sin(a), 0};
    const double lon = azimuth_ + (line == 1 ? 1 : -1) * M_PI / 4;
    return Vec3{std::cos(a) * std::cos(lon), std::cos(a) * std::sin(lon), std::sin(a)};
  };
  for (int line = 0; line < 3; ++line) {
    constexpr int n = 72;
    for (int i = 0; i < n; ++i) {
      const MapPoint m0 = project_to_map(circle_point(line, 2 * M_PI * i / n), azimuth_, kElevation);
      const MapPoint m1 = project_to_map(circle_point(line, 2 * M_PI * (i + 1) / n), azimuth_, kElevation);
      const bool front = m0.depth + m1.depth > 0;
      dl->AddLine(to_screen(m0, 1), to_screen(m1, 1), front ? IM_COL32(90, 110, 140, 255) : IM_COL32(60, 70, 90, 110));
    }
  }

  // Orientation marks (directions are in the domain's sky frame: x east, y north, z sky): the sky pole
  // and north on the equator, drawn faint when on the far side.
  for (const auto& [dir, label, colour] : {std::tuple{Vec3{0, 0, 1}, "sky", IM_COL32(120, 180, 255, 255)},
                                           std::tuple{Vec3{0, 1, 0}, "N", IM_COL32(235, 90, 80, 255)}}) {
    const MapPoint m = project_to_map(dir, azimuth_, kElevation);
    const ImVec2 s = to_screen(m, 1.0);
    const ImU32 col = m.depth >= 0 ? colour : (colour & 0x00ffffffu) | 0x70000000u;
    dl->AddLine(c, s, col, 1.0f);
    // The label inside the disc, so a mark on the rim does not spill over the map's edge.
    const float tw = ImGui::CalcTextSize(label).x;
    dl->AddText(ImVec2(s.x > c.x ? s.x - tw - 3 : s.x + 3, s.y - 14), col, label);
  }

  const ImVec2 mouse = ImGui::GetIO().MousePos;
  int hit = -1;
  float hit_d2 = 8.f * 8.f;
  // Back hemisphere first so front dots are drawn over them.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < dirs_.size(); ++i) {
      const MapPoint m = project_to_map(dirs_[i], azimuth_, kElevation);
      const bool front = m.depth >= 0;
      if (front != (pass == 1)) continue;
      const double r = shell_count_ > 1 ? 1.0 - 0.35 * shells_[i] / (shell_count_ - 1) : 1.0;
      const ImVec2 s = to_screen(m, r);
      const bool is_neighbour = std::find(neighbours.begin(), neighbours.end(), int(i)) != neighbours.end();
      ImU32 col = front ? IM_COL32(170, 190, 220, 255) : IM_COL32(110, 120, 140, 120);
      float dot_r = front ? 2.5f : 1.8f;
      if (is_neighbour) {
        col = front ? IM_COL32(80, 220, 230, 255) : IM_COL32(60, 150, 160, 170);
        dot_r += 0.8f;
      }
      dl->AddCircleFilled(s, dot_r, col, 8);
      if (front && hovered) {
        const float dx = s.x - mouse.x, dy = s.y - mouse.y;
        if (dx * dx + dy * dy < hit_d2) {
          hit_d2 = dx * dx + dy * dy;
          hit = int(i);
        }
      }
    }
  }
  if (current >= 0 && current < int(dirs_.size())) {
    const MapPoint m = project_to_map(dirs_[std::size_t(current)], azimuth_, kElevation);
    const double r = shell_count_ > 1 ? 1.0 - 0.35 * shells_[std::size_t(current)] / (shell_count_ - 1) : 1.0;
    const ImVec2 s = to_screen(m, r);
    dl->AddCircleFilled(s, 5.f, IM_COL32(255, 210, 40, 255), 12);
    dl->AddCircle(s, 8.f, IM_COL32(255, 210, 40, 255), 16, 1.5f);
  }
  if (hit >= 0) {
    const MapPoint m = project_to_map(dirs_[std::size_t(hit)], azimuth_, kElevation);
    const double r = shell_count_ > 1 ? 1.0 - 0.35 * shells_[std::size_t(hit)] / (shell_count_ - 1) : 1.0;
    dl->AddCircle(to_screen(m, r), 6.f, IM_COL32(255, 255, 255, 255), 12, 1.5f);
    ImGui::SetTooltip("camera %d (click to jump)", hit);
  }
  return clicked ? hit : -1;
}

}  // namespace panoptes::ui
