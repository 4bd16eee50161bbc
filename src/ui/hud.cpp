#include "ui/hud.hpp"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "player/keys.hpp"

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
  for (const auto& c : manifest.cameras) {
    dirs.push_back(c.position - c.look_at);
    shells.push_back(c.labels.shell);
  }
  minimap_.set_cameras(std::move(dirs), std::move(shells));
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
    // At most ~60 % of the width (and 440 px) so long messages wrap instead of covering the frame.
    const float panel_w = std::max(std::min(vw * 0.6f, 440.f), std::min(vw, 240.f));
    ImGui::SetNextWindowPos(ImVec2(vw - pad, pad), ImGuiCond_Always, ImVec2(1, 0));
    ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(panel_w, vh));
    ImGui::SetNextWindowBgAlpha(0.72f);
    if (ImGui::Begin("##status", nullptr, kOverlayFlags)) {
      ImGui::PushTextWrapPos(panel_w - 2 * ImGui::GetStyle().WindowPadding.x);
      panel_drawn_ = true;
      remember_window();
      const auto& sel = info.selection;
      const auto& cam = m.cameras[std::size_t(sel.camera)];
      const auto& task = m.tasks[std::size_t(sel.task)];
      ImGui::Text("t = %.4g   frame %d of %d", info.sim_time, sel.frame, info.frame_count);
      ImGui::Text("camera %d%s%s  lat %+.1f  lon %+.1f  shell %d", sel.camera, cam.labels.patch.empty() ? "" : " ",
                  cam.labels.patch.c_str(), cam.labels.lat_deg, cam.labels.lon_deg, cam.labels.shell);
      ImGui::Text("task %d of %d: %s", sel.task, int(m.tasks.size()), task.name.c_str());
      const std::string params = format_parameters(m, task);
      if (!params.empty()) ImGui::Text("  %s", params.c_str());
      if (info.active_axis >= 0 && info.active_axis < int(m.axes.size()))
        ImGui::Text("PgUp/PgDn axis: %s", m.axes[std::size_t(info.active_axis)].name.c_str());
      ImGui::Text("%s x%g%s%s", info.playing ? "playing" : "paused", info.speed, info.direction < 0 ? " reverse" : "",
                  info.loop ? "  loop" : "");
      ImGui::Text("display %.1f fps   zoom x%.2g", info.display_fps, info.zoom);
      if (info.have_switch)
        ImGui::Text("last switch %.2f ms (%s)  p99 %.2f ms", info.last_switch_ms,
                    info.last_switch_hit ? "prefetched" : "decoded", info.switch_p99_ms);
      else
        ImGui::TextDisabled("last switch: none yet");
      const std::int64_t shown = info.cache_hits + info.cache_misses;
      ImGui::Text("cache %s / %s, hits %.0f%%", megabytes(info.cache_bytes).c_str(),
                  megabytes(info.cache_capacity).c_str(), shown ? 100.0 * double(info.cache_hits) / double(shown) : 0.0);
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
      ImGui::TextDisabled("H / F1: help   renderer: %s", info.renderer.c_str());
      ImGui::PopTextWrapPos();
    }
    ImGui::End();

    // Mini-map, bottom right above the slider.
    const float map = std::clamp(std::min(vw, vh) * 0.28f, 90.f, 220.f);
    const float slider_h = ImGui::GetFrameHeightWithSpacing() + 2 * ImGui::GetStyle().WindowPadding.y;
    ImGui::SetNextWindowPos(ImVec2(vw - pad, vh - slider_h - pad), ImGuiCond_Always, ImVec2(1, 1));
    ImGui::SetNextWindowBgAlpha(0.5f);
    if (ImGui::Begin("##minimap", nullptr, kOverlayFlags)) {
      remember_window();
      req.jump_camera = minimap_.draw(info.selection.camera, info.neighbours, map);
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
  ImGui::SetNextWindowPos(ImVec2(vw / 2, vh / 2), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(vw * 0.95f, vh * 0.9f));
  ImGui::SetNextWindowBgAlpha(0.9f);
  if (ImGui::Begin("Panoptes keys (H / F1 closes)", &show_help,
                   ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse)) {
    remember_window();
    if (ImGui::BeginTable("##keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
      for (const auto& b : player::key_bindings()) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(b.key.data(), b.key.data() + b.key.size());
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(b.description.data(), b.description.data() + b.description.size());
      }
      const char* mouse[][2] = {{"left drag", "rotate: snap to the camera nearest the dragged direction"},
                                {"wheel", "magnify around the cursor"},
                                {"right drag", "pan the magnified frame"},
                                {"mini-map click", "jump to that camera"},
                                {"I", "hide / show the HUD"}};
      for (const auto& row : mouse) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(row[0]);
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(row[1]);
      }
      ImGui::EndTable();
    }
  }
  ImGui::End();
}

}  // namespace panoptes::ui
