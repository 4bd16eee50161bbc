#include "ui/hud.hpp"

#include "ui/hud_text.hpp"
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>
#include <vector>

#include "player/controls.hpp"
#include "player/keys.hpp"
#include "player/legend.hpp"
#include "player/look.hpp"

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

std::vector<Vec3> minimap_directions(const store::Manifest& manifest) {
  // East, north, sky as world vectors (a proper rotation, so the map keeps the rig's handedness).
  Vec3 east{1, 0, 0}, north{0, 1, 0}, sky{0, 0, 1};
  if (manifest.domain.up_axis == "z_down") east = {0, 1, 0}, north = {1, 0, 0}, sky = {0, 0, -1};
  const auto& params = manifest.rig.parameters;
  if (manifest.rig.kind == "cinema" && params.is_object() && params.contains("pole") && params["pole"].is_array() &&
      params["pole"].size() == 3 && params["pole"][0].is_number() && params["pole"][1].is_number() &&
      params["pole"][2].is_number()) {
    const Vec3 pole{params["pole"][0].get<double>(), params["pole"][1].get<double>(), params["pole"][2].get<double>()};
    if (std::abs(pole.y) > 0.5) east = {0, 0, 1}, north = {1, 0, 0}, sky = {0, 1, 0};
    if (std::abs(pole.x) > 0.5) east = {0, 1, 0}, north = {0, 0, 1}, sky = {1, 0, 0};
  }
  std::vector<Vec3> dirs;
  dirs.reserve(manifest.cameras.size());
  for (const auto& c : manifest.cameras) {
    const Vec3 d = c.position - c.look_at;
    dirs.push_back({dot(d, east), dot(d, north), dot(d, sky)});
  }
  return dirs;
}

Hud::Hud(const store::Manifest& manifest) : help_mode_(help_mode(manifest)), help_rows_(help_rows(help_mode_, &manifest)) {
  std::vector<Vec3> dirs = minimap_directions(manifest);
  std::vector<int> shells;
  for (const auto& c : manifest.cameras) shells.push_back(c.labels.shell);
  const bool z_down = manifest.domain.up_axis == "z_down";
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
      ImGui::Text("%s   frame %d of %d   %s x%.2g%s%s", player::time_text(m, info.sim_time).c_str(), sel.frame, info.frame_count,
                  info.playing ? "playing" : "paused", info.speed, info.direction < 0 ? " reverse" : "", info.loop ? "" : " once");
      // A database written before frame checks cannot prove its frames (issue 44): say so, in amber,
      // instead of letting a frame that decodes pass for a verified one.
      if (!m.frame_checks.recorded())
        ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "frames unverified (written before frame checks)");
      const std::string shell = info.shell_count > 1 ? "   shell " + std::to_string(cam.labels.shell) : "";
      if (!info.position_label.empty())
        ImGui::Text("camera %d   %s%s", sel.camera, info.position_label.c_str(), shell.c_str());
      else
        ImGui::Text("camera %d%s%s   lat %s  lon %s%s", sel.camera, cam.labels.patch.empty() ? "" : " ",
                    cam.labels.patch.c_str(), signed_degrees(cam.labels.lat_deg).c_str(),
                    signed_degrees(cam.labels.lon_deg).c_str(), shell.c_str());
      if (!info.look_label.empty()) ImGui::TextUnformatted(info.look_label.c_str());
      if (!info.world_label.empty()) ImGui::TextUnformatted(info.world_label.c_str());
      const std::string params = format_parameters(m, task);
      // Numbered from 1, as the digit keys select them.
      ImGui::Text("task %d of %d: %s%s%s", sel.task + 1, int(m.tasks.size()), task.name.c_str(),
                  params.empty() ? "" : "   ", params.c_str());
      // Inside a lattice or along a path PgUp/PgDn walk up and down: no axis to step there.
      if (help_mode_ != HelpMode::walk && info.active_axis >= 0 && info.active_axis < int(m.axes.size()))
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
        // From the key press as the display server stamped it to the frame presented: what the user
        // waited (the engine's own switch time leaves out the queueing and the drawing).
        if (info.have_input_latency)
          ImGui::Text("input -> screen %.1f ms  p99 %.1f ms (%d inputs)", info.input_latency_ms, info.input_latency_p99_ms,
                      info.inputs_measured);
        else
          ImGui::TextDisabled("input -> screen: no input yet");
        if (info.have_switch)
          ImGui::Text("last switch: frame %s", info.last_switch_hit ? "prefetched" : "decoded on demand");
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
    // Scales with the window: 16 % of its width (256 px on a 1600-px window, issue 32.2), but never more
    // than 40 % of its height, so wide short windows keep room for the panel above it.
    const float map = std::clamp(std::min(vw * 0.16f, vh * 0.4f), 80.f, 400.f);
    const float slider_h = ImGui::GetFrameHeightWithSpacing() + 2 * ImGui::GetStyle().WindowPadding.y;
    ImGui::SetNextWindowPos(ImVec2(vw - pad, vh - slider_h - pad), ImGuiCond_Always, ImVec2(1, 1));
    ImGui::SetNextWindowBgAlpha(0.35f);
    if (ImGui::Begin("##minimap", nullptr, kOverlayFlags)) {
      remember_window();
      if (!lattice_map_.empty()) {
        const Vec3& v = info.view_direction;
        req.jump_camera =
            lattice_map_.draw(info.selection.camera, info.neighbours, z_down_ ? Vec3{v.y, v.x, -v.z} : v, map, info.half_fov_deg);
      } else {
        req.jump_camera = minimap_.draw(info.selection.camera, info.neighbours, map);
      }
    }
    ImGui::End();

    draw_legend(info, vw, vh);

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

void Hud::draw_legend(const HudInfo& info, float vw, float vh) {
  const auto bars = player::task_legend(*info.manifest, info.selection.task, info.selection.frame);
  legend_text_.clear();
  for (const auto& bar : bars) legend_text_ += (legend_text_.empty() ? "" : "; ") + player::legend_range_text(bar);
  if (bars.empty()) return;
  // Bottom left, above the time slider: the top-left corner belongs to the frame (and its stamp in
  // tests), the right side to the status panel and the mini-map.
  const float pad = 8, scale = ImGui::GetIO().FontGlobalScale;
  const float slider_h = ImGui::GetFrameHeightWithSpacing() + 2 * ImGui::GetStyle().WindowPadding.y;
  const float bar_w = std::clamp(vw * 0.22f, 120.f, 260.f * scale), bar_h = ImGui::GetTextLineHeight();
  ImGui::SetNextWindowPos(ImVec2(pad, vh - slider_h - pad), ImGuiCond_Always, ImVec2(0, 1));
  ImGui::SetNextWindowBgAlpha(0.6f);
  if (!ImGui::Begin("##legend", nullptr, kOverlayFlags)) {
    ImGui::End();
    return;
  }
  remember_window();
  for (const player::LegendBar& bar : bars) {
    const std::string units = bar.physical && !bar.units.empty() ? "  [" + bar.units + "]" : "";
    ImGui::Text("%s%s", bar.label.c_str(), units.c_str());
    ImDrawList* draw = ImGui::GetWindowDrawList();
    const ImVec2 p = ImGui::GetCursorScreenPos();
    if (bar.isovalue) {
      const auto c = bar.colours.empty() ? std::array<float, 3>{0.8f, 0.8f, 0.8f} : bar.colours[0];
      draw->AddRectFilled(p, ImVec2(p.x + bar_h * 2, p.y + bar_h), ImGui::GetColorU32(ImVec4(c[0], c[1], c[2], 1)));
      ImGui::Dummy(ImVec2(bar_h * 2, bar_h));
      ImGui::SameLine();
      ImGui::TextUnformatted(player::legend_range_text(bar).c_str());
      continue;
    }
    if (!bar.colours.empty()) {
      const int n = int(bar.colours.size());
      for (int i = 0; i + 1 < n; ++i) {
        const auto& a = bar.colours[std::size_t(i)];
        const auto& b = bar.colours[std::size_t(i + 1)];
        const float x0 = p.x + bar_w * float(i) / float(n - 1), x1 = p.x + bar_w * float(i + 1) / float(n - 1);
        const ImU32 ca = ImGui::GetColorU32(ImVec4(a[0], a[1], a[2], 1)), cb = ImGui::GetColorU32(ImVec4(b[0], b[1], b[2], 1));
        draw->AddRectFilledMultiColor(ImVec2(x0, p.y), ImVec2(x1, p.y + bar_h), ca, cb, cb, ca);
      }
      draw->AddRect(p, ImVec2(p.x + bar_w, p.y + bar_h), ImGui::GetColorU32(ImVec4(0.55f, 0.6f, 0.7f, 1)));
      ImGui::Dummy(ImVec2(bar_w, bar_h));
    }
    // The window's ends under the bar's ends (fractions of the reference for older databases).
    const std::string lo = player::legend_number(bar.lo), hi = player::legend_number(bar.hi) + (bar.physical ? "" : " x ref");
    ImGui::TextUnformatted(lo.c_str());
    const float hi_w = ImGui::CalcTextSize(hi.c_str()).x;
    const float left = ImGui::GetStyle().WindowPadding.x;
    ImGui::SameLine(std::max(left + ImGui::CalcTextSize(lo.c_str()).x + 12, left + bar_w - hi_w));
    ImGui::TextUnformatted(hi.c_str());
    // What the scale follows, and when it just changed by how much (issue 41): a frame that looks
    // brighter because its window shrank says so instead of pulsing silently.
    std::string other;
    for (const player::LegendBar& o : bars)
      if (&o != &bar) other = o.field;
    // The mode in grey, the change (if any) on its own line in amber: one line would make the
    // legend twice as wide over the picture.
    const std::string mode = player::legend_scale_mode_text(bar, other), change = player::legend_change_text(bar);
    if (!mode.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.62f, 0.66f, 0.74f, 1));
      ImGui::TextUnformatted(("scale: " + mode).c_str());
      ImGui::PopStyleColor();
    }
    if (!change.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.78f, 0.3f, 1));
      ImGui::TextUnformatted(change.c_str());
      ImGui::PopStyleColor();
    }
  }
  ImGui::End();
}

HelpMode help_mode(const store::Manifest& m) {
  if (!player::is_equirectangular(m)) return HelpMode::rig;
  const auto& params = m.rig.parameters;
  const bool walkable = player::lattice_shape(m)[0] > 0 || (params.contains("path") && params["path"] == true);
  return walkable ? HelpMode::walk : HelpMode::look;
}

namespace {
player::ViewMode view_mode_of(HelpMode mode) {
  switch (mode) {
    case HelpMode::rig: return player::ViewMode::sphere;
    case HelpMode::look: return player::ViewMode::panorama;
    case HelpMode::walk: return player::ViewMode::lattice;
  }
  return player::ViewMode::sphere;
}
}  // namespace

std::vector<HelpRow> help_rows(HelpMode mode, const store::Manifest* manifest) {
  std::vector<HelpRow> rows;
  for (const auto& kb : player::key_bindings()) {
    if (manifest && !player::usable(kb.action, view_mode_of(mode), *manifest)) continue;
    // The wording of the one key table (player/controls: what `panoptes keys --mode` and the browser
    // show); a key that does nothing in this mode (A inside a lattice) has no row.
    player::KeyBinding b = kb;
    b.description = player::description(kb, view_mode_of(mode));
    if (b.description.empty()) continue;
    // The nine digit keys are one row, numbered as the HUD numbers tasks.
    if (b.action >= player::Action::task_1 && b.action <= player::Action::task_9) {
      if (b.action == player::Action::task_1) rows.push_back({"1 .. 9", "select task 1 .. 9 (numbered as in the HUD)"});
      continue;
    }
    // Keys that do the same thing share a row ("H / F1", "Escape / Q", "+ / =").
    if (!rows.empty()) {
      HelpRow& last = rows.back();
      const std::string_view what = b.description;
      if (what == last.what || what.rfind("same as", 0) == 0) {
        last.key += " / " + std::string(b.key);
        continue;
      }
    }
    rows.push_back({std::string(b.key), std::string(b.description)});
  }
  if (mode == HelpMode::rig) {
    for (const auto& r : {HelpRow{"left drag", "rotate: snap to the camera nearest the dragged direction"},
                          HelpRow{"wheel", "magnify around the cursor"}, HelpRow{"right drag", "pan the magnified frame"},
                          HelpRow{"mini-map click", "jump to that camera"}})
      rows.push_back(r);
  } else {
    if (mode == HelpMode::walk)
      rows.push_back({"double-click", "step toward the clicked direction (Shift: step away from it)"});
    for (const auto& r : {HelpRow{"left drag", "look around (the scene follows the pointer)"},
                          HelpRow{"wheel", "narrower / wider field of view"},
                          HelpRow{"mini-map click", "jump to that camera"}})
      rows.push_back(r);
  }
  return rows;
}

HelpLayout help_layout(int rows, float row_h, float pair_w, float avail_w, float avail_h, float font_scale) {
  HelpLayout l;
  const auto height = [&](int pairs, float scale) { return float((rows + pairs - 1) / pairs) * row_h * scale; };
  // The fewest column pairs whose height fits, as long as they fit the width.
  while (l.pairs < 3 && height(l.pairs, 1) > avail_h && float(l.pairs + 1) * pair_w <= avail_w) ++l.pairs;
  // Still too tall (or too wide): shrink the text, but not below ImGui's bitmap font at its own size
  // (smaller is unreadable); whatever still does not fit scrolls.
  const float fit = std::min(avail_h / std::max(height(l.pairs, 1), 1.f), avail_w / std::max(float(l.pairs) * pair_w, 1.f));
  if (fit < 1) l.scale = std::max(fit, std::min(1.f, 1.f / std::max(font_scale, 1e-3f)));
  l.fits = l.scale <= fit * (1 + 1e-6f);
  return l;
}

void Hud::draw_help(float vw, float vh) {
  const std::vector<HelpRow>& rows = help_rows_;
  const ImGuiStyle& style = ImGui::GetStyle();
  float key_w = 0, what_w = 0;
  for (const HelpRow& r : rows) {
    key_w = std::max(key_w, ImGui::CalcTextSize(r.key.c_str()).x);
    what_w = std::max(what_w, ImGui::CalcTextSize(r.what.c_str()).x);
  }
  const float pair_w = key_w + what_w + 4 * style.CellPadding.x + style.ItemSpacing.x;
  const float row_h = ImGui::GetTextLineHeight() + 2 * style.CellPadding.y;
  const float chrome_w = 2 * style.WindowPadding.x, chrome_h = 2 * style.WindowPadding.y + ImGui::GetFrameHeight();
  // Between the top edge and the time slider (when the HUD shows it), so no line hides under it.
  const float pad = 8;
  const float slider_h = show_panel ? ImGui::GetFrameHeightWithSpacing() + 2 * style.WindowPadding.y : 0;
  const float avail_h = vh - slider_h - 2 * pad, avail_w = vw - 2 * pad;
  const HelpLayout layout =
      help_layout(int(rows.size()), row_h, pair_w, avail_w - chrome_w, avail_h - chrome_h, ImGui::GetIO().FontGlobalScale);
  last_help_layout_ = layout;
  ImGui::SetNextWindowPos(ImVec2(vw / 2, pad + avail_h / 2), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(avail_w, avail_h));
  ImGui::SetNextWindowBgAlpha(0.9f);
  // Scroll bars only when it cannot fit: a sub-pixel overflow of the rounded auto-fit size would show one.
  const ImGuiWindowFlags scroll = layout.fits ? ImGuiWindowFlags_NoScrollbar : ImGuiWindowFlags_HorizontalScrollbar;
  if (ImGui::Begin("Panoptes keys (H / F1 closes)", &show_help,
                   ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse | scroll)) {
    remember_window();
    ImGui::SetWindowFontScale(layout.scale);
    const int pairs = layout.pairs;
    const int per_column = (int(rows.size()) + pairs - 1) / pairs;
    if (ImGui::BeginTable("##keys", 2 * pairs, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
      for (int r = 0; r < per_column; ++r) {
        ImGui::TableNextRow();
        for (int p = 0; p < pairs; ++p) {
          const int i = p * per_column + r;
          ImGui::TableNextColumn();
          if (i < int(rows.size())) ImGui::TextUnformatted(rows[std::size_t(i)].key.c_str());
          ImGui::TableNextColumn();
          if (i < int(rows.size())) ImGui::TextUnformatted(rows[std::size_t(i)].what.c_str());
        }
      }
      ImGui::EndTable();
    }
    // Less than a pixel hides nothing (the window's auto-fit size is rounded to whole pixels).
    help_fits_ = ImGui::GetScrollMaxY() < 1 && ImGui::GetScrollMaxX() < 1;
  }
  ImGui::End();
}

float Hud::scale_for(float vw, float vh) { return std::clamp(std::min(vw, vh) / 800.f, 1.f, 2.f); }

}  // namespace panoptes::ui
