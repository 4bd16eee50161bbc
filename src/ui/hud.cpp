#include "ui/hud.hpp"

#include "ui/hud_text.hpp"
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>
#include <vector>

#include "player/keys.hpp"
#include "ui/hud_text.hpp"

namespace panoptes::ui {
namespace {

constexpr ImGuiWindowFlags kOverlayFlags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                           ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                           ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove;

std::string format_parameters(const store::Manifest& m, const store::TaskEntry& task) {
  std::string out;
  char buf[128];
  for (const auto& pos : task.axes) {
    const int a = m.find_axis(pos.axis);
    if (a < 0 || pos.index < 0 || pos.index >= int(m.axes[std::size_t(a)].values.size())) continue;
    const auto& axis = m.axes[std::size_t(a)];
    std::snprintf(buf, sizeof buf, "%s%s = %g%s%s", out.empty() ? "" : ", ", axis.name.c_str(),
                  axis.values[std::size_t(pos.index)], axis.units.empty() ? "" : " ", axis.units.c_str());
    out += buf;
  }
  return out;
}

std::string megabytes(std::size_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f MB", double(bytes) / (1024.0 * 1024.0));
  return buf;
}

}  // namespace

Hud::Hud(const store::Manifest& manifest) {
  std::vector<Vec3> dirs;
  std::vector<int> shells;
  dirs.reserve(manifest.cameras.size());
  // The mini-map draws the sky at the top: directions go into the domain's sky frame (east, north,
  // sky), the same frame camera::SkyFrame lays rigs out in (z_down: east = +y, north = +x, sky = −z).
  const bool z_down = manifest.domain.up_axis == "z_down";
  for (const auto& c : manifest.cameras) {
    const Vec3 d = c.position - c.look_at;
    dirs.push_back(z_down ? Vec3{d.y, d.x, -d.z} : d);
    shells.push_back(c.labels.shell);
  }
  minimap_.set_cameras(std::move(dirs), std::move(shells));
  // Rigs inside the volume (issue 14) get a 3-D overview of the box and the cameras instead.
  const auto& params = manifest.rig.parameters;
  if (params.contains("lattice") || (params.contains("path") && params["path"] == true)) {
    auto sky = [&](const Vec3& p) { return z_down ? Vec3{p.y, p.x, -p.z} : p; };
    std::vector<Vec3> positions;
    for (const auto& c : manifest.cameras) positions.push_back(sky(c.position));
    const auto& d = manifest.domain;
    const Vec3 hi{d.origin.x + double(std::max<std::int64_t>(d.dims[0] - 1, 0)) * d.spacing.x,
                  d.origin.y + double(std::max<std::int64_t>(d.dims[1] - 1, 0)) * d.spacing.y,
                  d.origin.z + double(std::max<std::int64_t>(d.dims[2] - 1, 0)) * d.spacing.z};
    lattice_map_.set_scene(std::move(positions), sky(d.origin), sky(hi));
    z_down_ = z_down;
  }
}

void Hud::notify(std::string text, bool error) {
  message_ = std::move(text);
  message_error_ = error;
  message_until_ = ImGui::GetTime() + (error ? 6.0 : 3.0);
}

void Hud::remember_window() {
  const ImVec2 p = ImGui::GetWindowPos(), sz = ImGui::GetWindowSize();
  boxes_.push_back({p.x, p.y, p.x + sz.x, p.y + sz.y});
}

bool Hud::covers(float x, float y) const {
  for (const auto& b : boxes_)
    if (x >= b.x0 && x < b.x1 && y >= b.y0 && y < b.y1) return true;
  return false;
}

HudRequests Hud::draw(const HudInfo& info, float vw, float vh) {
  HudRequests req;
  panel_drawn_ = false;
  boxes_.clear();
  const store::Manifest& m = *info.manifest;
  const float pad = 8;

  if (show_panel) {
    // Status panel, top right: the top-left corner belongs to the frame (and its stamp in tests).
    // Compact by default (4 lines), so the HUD hides only a small part of the picture; the session
    // statistics are one click away under "details". Long messages wrap at ~45 % of the width.
    const float scale = ImGui::GetIO().FontGlobalScale;
    const float panel_w = std::max(std::min(vw * 0.45f, 460.f * scale), std::min(vw, 240.f));
    ImGui::SetNextWindowPos(ImVec2(vw - pad, pad), ImGuiCond_Always, ImVec2(1, 0));
    ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(panel_w, vh * 0.6f));
    ImGui::SetNextWindowBgAlpha(0.6f);
    if (ImGui::Begin("##status", nullptr, kOverlayFlags)) {
      ImGui::PushTextWrapPos(panel_w - 2 * ImGui::GetStyle().WindowPadding.x);
      panel_drawn_ = true;
      remember_window();
      const auto& sel = info.selection;
      const auto& cam = m.cameras[std::size_t(sel.camera)];
      const auto& task = m.tasks[std::size_t(sel.task)];
      ImGui::Text("t = %.4g   frame %d of %d   %s x%.2g%s%s", info.sim_time + 0.0, sel.frame, info.frame_count,
                  info.playing ? "playing" : "paused", info.speed, info.direction < 0 ? " reverse" : "", info.loop ? "" : " once");
      const std::string shell = info.shell_count > 1 ? "   shell " + std::to_string(cam.labels.shell) : "";
      if (!info.position_label.empty())
        ImGui::Text("camera %d   %s%s", sel.camera, info.position_label.c_str(), shell.c_str());
      else
        ImGui::Text("camera %d%s%s   lat %s  lon %s%s", sel.camera, cam.labels.patch.empty() ? "" : " ",
                    cam.labels.patch.c_str(), signed_degrees(cam.labels.lat_deg).c_str(),
                    signed_degrees(cam.labels.lon_deg).c_str(), shell.c_str());
      if (!info.look_label.empty()) ImGui::TextUnformatted(info.look_label.c_str());
      const std::string params = format_parameters(m, task);
      ImGui::Text("task %d of %d: %s%s%s", sel.task, int(m.tasks.size()), task.name.c_str(),
                  params.empty() ? "" : "   ", params.c_str());
      if (info.active_axis >= 0 && info.active_axis < int(m.axes.size()))
        ImGui::Text("PgUp/PgDn axis: %s", m.axes[std::size_t(info.active_axis)].name.c_str());
      if (info.recording) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.3f, 0.3f, 1));
        ImGui::TextWrapped("REC %s", info.recording_path.c_str());
        ImGui::PopStyleColor();
      }
      if (info.status != player::FrameStatus::ok) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.4f, 0.3f, 1));
        ImGui::TextWrapped("stream %s: %s", std::string(player::to_string(info.status)).c_str(),
                           info.status_message.c_str());
        ImGui::PopStyleColor();
      }
      if (ImGui::TreeNodeEx("details", ImGuiTreeNodeFlags_NoTreePushOnOpen)) {
        ImGui::Text("display %.1f fps   zoom x%.2g", info.display_fps, info.zoom);
        if (info.have_switch)
          ImGui::Text("last switch %.2f ms (%s)  p99 %.2f ms", info.last_switch_ms,
                      info.last_switch_hit ? "prefetched" : "decoded", info.switch_p99_ms);
        else
          ImGui::TextDisabled("last switch: none yet");
        const std::int64_t shown = info.cache_hits + info.cache_misses;
        ImGui::Text("cache %s / %s, hits %.0f%%", megabytes(info.cache_bytes).c_str(),
                    megabytes(info.cache_capacity).c_str(), shown ? 100.0 * double(info.cache_hits) / double(shown) : 0.0);
        ImGui::TextDisabled("renderer: %s", info.renderer.c_str());
      }
      ImGui::SameLine();
      ImGui::TextDisabled("  H: help   I: hide HUD");
      ImGui::PopTextWrapPos();
    }
    ImGui::End();

    // Mini-map, bottom right above the slider.
    // Scales with the window: ~16 % of its smaller side (about 3 % of the picture's area).
    const float map = std::clamp(std::min(vw, vh) * 0.16f, 80.f, 320.f);
    const float slider_h = ImGui::GetFrameHeightWithSpacing() + 2 * ImGui::GetStyle().WindowPadding.y;
    ImGui::SetNextWindowPos(ImVec2(vw - pad, vh - slider_h - pad), ImGuiCond_Always, ImVec2(1, 1));
    ImGui::SetNextWindowBgAlpha(0.35f);
    if (ImGui::Begin("##minimap", nullptr, kOverlayFlags)) {
      remember_window();
      if (!lattice_map_.empty()) {
        const Vec3& v = info.view_direction;
        req.jump_camera = lattice_map_.draw(info.selection.camera, info.neighbours, z_down_ ? Vec3{v.y, v.x, -v.z} : v, map);
      } else {
        req.jump_camera = minimap_.draw(info.selection.camera, info.neighbours, map);
      }
    }
    ImGui::End();

    // Time slider along the bottom edge.
    ImGui::SetNextWindowPos(ImVec2(0, vh), ImGuiCond_Always, ImVec2(0, 1));
    ImGui::SetNextWindowSize(ImVec2(vw, 0), ImGuiCond_Always);
    ImGui::SetNextWindowBgAlpha(0.6f);
    if (ImGui::Begin("##timeline", nullptr, kOverlayFlags & ~ImGuiWindowFlags_AlwaysAutoResize)) {
      remember_window();
      if (ImGui::Button(info.playing ? "Pause" : "Play")) req.toggle_play = true;
      ImGui::SameLine();
      ImGui::SetNextItemWidth(-1);
      int frame = info.selection.frame;
      if (ImGui::SliderInt("##frame", &frame, 0, std::max(0, info.frame_count - 1), "frame %d"))
        req.seek = frame;
    }
    ImGui::End();
  }

  if (show_help) draw_help(vw, vh);

  if (!message_.empty() && ImGui::GetTime() < message_until_) {
    ImGui::SetNextWindowPos(ImVec2(vw / 2, vh * 0.8f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(vw * 0.95f, vh * 0.5f));
    ImGui::SetNextWindowBgAlpha(0.8f);
    if (ImGui::Begin("##message", nullptr, kOverlayFlags)) {
      remember_window();
      // Long paths wrap instead of running off the window.
      ImGui::PushTextWrapPos(vw * 0.95f - 2 * ImGui::GetStyle().WindowPadding.x);
      if (message_error_) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.45f, 0.35f, 1));
      ImGui::TextUnformatted(message_.c_str());
      if (message_error_) ImGui::PopStyleColor();
      ImGui::PopTextWrapPos();
    }
    ImGui::End();
  }
  return req;
}

void Hud::draw_help(float vw, float vh) {
  struct Row {
    std::string_view key, what;
  };
  std::vector<Row> rows;
  for (const auto& b : player::key_bindings()) rows.push_back({b.key, b.description});
  for (const auto& r : {Row{"left drag", "rotate: snap to the camera nearest the dragged direction"},
                        Row{"wheel", "magnify around the cursor"}, Row{"right drag", "pan the magnified frame"},
                        Row{"mini-map click", "jump to that camera"}})
    rows.push_back(r);
  // Always fits the window: 1, 2 or 3 key/description column pairs — the fewest that fit the height,
  // as long as they fit the width — and whatever still does not fit scrolls (shrinking ImGui's bitmap
  // font makes it unreadable, so it is not shrunk).
  const ImGuiStyle& style = ImGui::GetStyle();
  float key_w = 0, what_w = 0;
  for (const Row& r : rows) {
    key_w = std::max(key_w, ImGui::CalcTextSize(r.key.data(), r.key.data() + r.key.size()).x);
    what_w = std::max(what_w, ImGui::CalcTextSize(r.what.data(), r.what.data() + r.what.size()).x);
  }
  const float pair_w = key_w + what_w + 4 * style.CellPadding.x + style.ItemSpacing.x;
  const float row_h = ImGui::GetTextLineHeight() + 2 * style.CellPadding.y;
  const float chrome_w = 2 * style.WindowPadding.x, chrome_h = 2 * style.WindowPadding.y + ImGui::GetFrameHeight();
  int pairs = 1;
  while (pairs < 3 && float((int(rows.size()) + pairs - 1) / pairs) * row_h > vh * 0.95f - chrome_h &&
         float(pairs + 1) * pair_w <= vw * 0.95f - chrome_w)
    ++pairs;
  ImGui::SetNextWindowPos(ImVec2(vw / 2, vh / 2), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(vw * 0.98f, vh * 0.95f));
  ImGui::SetNextWindowBgAlpha(0.9f);
  if (ImGui::Begin("Panoptes keys (H / F1 closes)", &show_help,
                   ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse |
                       ImGuiWindowFlags_HorizontalScrollbar)) {
    remember_window();
    const int per_column = (int(rows.size()) + pairs - 1) / pairs;
    if (ImGui::BeginTable("##keys", 2 * pairs, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
      for (int r = 0; r < per_column; ++r) {
        ImGui::TableNextRow();
        for (int p = 0; p < pairs; ++p) {
          const int i = p * per_column + r;
          ImGui::TableNextColumn();
          if (i < int(rows.size())) ImGui::TextUnformatted(rows[std::size_t(i)].key.data(), rows[std::size_t(i)].key.data() + rows[std::size_t(i)].key.size());
          ImGui::TableNextColumn();
          if (i < int(rows.size())) ImGui::TextUnformatted(rows[std::size_t(i)].what.data(), rows[std::size_t(i)].what.data() + rows[std::size_t(i)].what.size());
        }
      }
      ImGui::EndTable();
    }
  }
  ImGui::End();
}

float Hud::scale_for(float vw, float vh) { return std::clamp(std::min(vw, vh) / 800.f, 1.f, 2.f); }

}  // namespace panoptes::ui
