#pragma once
// The Dear ImGui overlay: status panel, rig mini-map, time slider, help overlay and short messages.
// It only reads a HudInfo snapshot and returns what the user asked for; the window applies it.
#include <string>
#include <vector>

#include "player/engine.hpp"
#include "store/manifest.hpp"
#include "ui/lattice_map.hpp"
#include "ui/minimap.hpp"

namespace panoptes::ui {

/// Everything the HUD shows, gathered by the window once per frame.
struct HudInfo {
  const store::Manifest* manifest = nullptr;
  player::Selection selection;
  int frame_count = 0;
  double sim_time = 0;
  int active_axis = -1;
  double speed = 1;
  bool playing = false, loop = true;
  int direction = 1;
  double display_fps = 0;
  bool have_switch = false;       ///< a switch has happened (latency below is meaningful)
  double last_switch_ms = 0;
  bool last_switch_hit = false;   ///< the last switch was served from the cache (prefetched)
  double switch_p99_ms = 0;
  bool have_input_latency = false;  ///< an input (key, click, wheel) has been shown on screen
  double input_latency_ms = 0;      ///< the last one: its own timestamp → the frame presented
  double input_latency_p99_ms = 0;
  int inputs_measured = 0;
  std::int64_t cache_hits = 0, cache_misses = 0;
  std::size_t cache_bytes = 0, cache_capacity = 0;
  double zoom = 1;
  bool recording = false;
  std::string recording_path;
  std::string renderer;
  player::FrameStatus status = player::FrameStatus::ok;
  std::string status_message;
  std::vector<int> neighbours;    ///< graph neighbours of the current camera (mini-map)
  int shell_count = 1;            ///< camera shells of the rig (the shell is shown only if > 1)
  std::string position_label;     ///< lattice cameras: "lattice (i, j, k) of NxNyxNz" instead of lat/lon
  std::string look_label;         ///< 360° streams: where the viewer looks (empty otherwise)
  std::string world_label;        ///< 360° streams: position in world units, compass heading, elevation
  Vec3 view_direction{0, 1, 0};   ///< world direction of the current view (lattice mini-map arrow)
  double half_fov_deg = 0;        ///< half the horizontal field of view (mini-map view cone; 0 = none)
};

/// What the user did in the HUD this frame.
struct HudRequests {
  int seek = -1;         ///< time slider moved to this frame
  int jump_camera = -1;  ///< mini-map click
  bool toggle_play = false;
};

/// One line of the help overlay: the key(s) and what they do.
struct HelpRow {
  std::string key, what;
};
/// How the database at hand uses the view keys (issue 32.2: help describes the keys as they act there).
enum class HelpMode {
  rig,       ///< perspective frames from cameras around the data: arrows rotate, + / - magnify
  look,      ///< 360° frames: drag looks around, + / - / wheel change the field of view
  walk,      ///< 360° frames on a lattice or path: additionally the arrows and PgUp / PgDn walk
};
/// The mode of a manifest (as the window decides: equirectangular projection, lattice or path rig).
HelpMode help_mode(const store::Manifest& manifest);
/// The help overlay's lines: the shared key table (player/keys.hpp) with the digit keys on one line and
/// keys of the same action sharing a line, worded for `mode`, then the mouse gestures. With a manifest,
/// keys that can change nothing in that database (player::usable: no parameter axes, one camera shell,
/// C on perspective frames) are left out.
std::vector<HelpRow> help_rows(HelpMode mode = HelpMode::rig, const store::Manifest* manifest = nullptr);

/// How the help overlay is laid out: key/description column pairs side by side and the text scale.
struct HelpLayout {
  int pairs = 1;
  float scale = 1;  ///< multiplies the HUD's font scale (< 1 only when columns alone do not fit)
  bool fits = true;  ///< every line fits at that scale (else the overlay scrolls)
};
/// The fewest pairs (1..3) whose rows fit `avail_h` while the pairs fit `avail_w` (row_h and pair_w as
/// measured at scale 1); if that still does not fit, a scale < 1, but never below the bitmap font's
/// own size (1 / font_scale).
HelpLayout help_layout(int rows, float row_h, float pair_w, float avail_w, float avail_h, float font_scale);

/// The direction from the rig centre towards each camera, in the sky frame the mini-map draws
/// (x east, y north, z the sky): the domain's sky (z_down: east = +y, north = +x, sky = -z), or, for
/// an imported Cinema database, the producer's pole (rig parameter "pole": ParaView's extractor turns
/// over +y), in the same proper frame as the cameras' lat/lon labels (cinema/import.cpp).
std::vector<Vec3> minimap_directions(const store::Manifest& manifest);

/// The overlay. Call draw() between SdlWindow::begin_imgui_frame() and render_imgui().
class Hud {
 public:
  /// Camera directions and shells for the mini-map (from the manifest).
  explicit Hud(const store::Manifest& manifest);

  HudRequests draw(const HudInfo& info, float viewport_w, float viewport_h);

  /// Font scale for a window of this size (set as ImGui's FontGlobalScale before the frame): the HUD
  /// grows with big windows and stays readable in small ones.
  static float scale_for(float viewport_w, float viewport_h);

  bool show_panel = true;  ///< status panel + mini-map + slider
  bool show_help = false;
  /// Shows `text` for a few seconds at the bottom centre (screenshot saved, recording errors, ...).
  void notify(std::string text, bool error = false);
  /// The last notice given to notify() (empty if none), whether or not still on screen.
  const std::string& last_notice() const { return message_; }
  /// The legend's ranges as last drawn (legend_range_text of each bar, joined by "; "; empty: none).
  const std::string& last_legend() const { return legend_text_; }
  /// True if the status panel was submitted in the last draw() (the window test checks it).
  bool panel_drawn() const { return panel_drawn_; }
  /// True if the help overlay showed every line without scrolling in the last draw() that drew it.
  bool help_fits() const { return help_fits_; }
  HelpLayout last_help_layout() const { return last_help_layout_; }
  /// True if window point (x, y) lies on one of the HUD's windows as drawn last frame. Mouse events
  /// there belong to the HUD; elsewhere they drive the view (hit-testing the event's own position
  /// rather than ImGui's idea of the pointer, which may lag or come from the global pointer state).
  bool covers(float x, float y) const;

 private:
  void draw_help(float viewport_w, float viewport_h);
  void draw_legend(const HudInfo& info, float viewport_w, float viewport_h);
  HelpMode help_mode_ = HelpMode::rig;
  std::vector<HelpRow> help_rows_;  // the help overlay's lines for this database
  MiniMap minimap_;
  LatticeMap lattice_map_;
  bool z_down_ = false;  ///< replaces the sphere map for rigs inside the volume (lattice, path)
  std::string message_;
  std::string legend_text_;
  bool message_error_ = false;
  double message_until_ = 0;
  bool panel_drawn_ = false;
  bool help_fits_ = false;
  HelpLayout last_help_layout_;
  struct Box {
    float x0, y0, x1, y1;
  };
  std::vector<Box> boxes_;
  void remember_window();  // records the current ImGui window's rectangle into boxes_
};

}  // namespace panoptes::ui
