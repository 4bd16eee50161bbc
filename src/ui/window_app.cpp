// run_window: the SDL2 + Dear ImGui front end over player::Engine.
// Sections (each marked "// --- name ---" below):
//   clocks        wall time; time tags for file names
//   window state  WindowApp and what it keeps between frames
//   script        scripted commands and their trace
//   actions       zoom, facing the action, a step toward a click, the key dispatch
//   events        SDL events: keys, wheel, drags, clicks, resizes
//   hud           the value readout, HUD requests and statistics, what the HUD shows
//   outputs       file names, recording (recorder.hpp), screenshots
//   frame loop    WindowApp::run: events, upload, draw, record, the session's summary
//   entry         run_window: checks before any window opens, the window's size
#include "ui/window_app.hpp"

#include <SDL.h>
#include <imgui.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backends/imgui_impl_sdl.h"
#include "core/error.hpp"
#include "core/png.hpp"
#include "player/engine.hpp"
#include "player/controls.hpp"
#include "player/face_action.hpp"
#include "player/step_toward.hpp"
#include "player/value_readout.hpp"
#include "player/headless.hpp"
#include "player/playback_rule.hpp"
#include "player/trace.hpp"
#include "ui/drag_rotation.hpp"
#include "ui/look_mesh.hpp"
#include "ui/frame_loop.hpp"
#include "ui/hud.hpp"
#include "ui/hud_text.hpp"
#include "ui/input_latency.hpp"
#include "ui/recorder.hpp"
#include "ui/sdl_keys.hpp"
#include "ui/sdl_window.hpp"
#include "ui/view_transform.hpp"
#include "ui/yuv_texture.hpp"

namespace panoptes::ui {
// --- clocks ---
namespace {

double wall_seconds() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
}

// Local time stamp for output file names, e.g. 20261121-224801.
std::string time_tag() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

// --- window state ---
class WindowApp {
 public:
  WindowApp(player::Engine& engine, SdlWindow& window, const WindowOptions& options,
            std::vector<player::ScriptCommand> script, player::VirtualClock& vclock)
      : engine_(engine),
        window_(window),
        options_(options),
        script_(std::move(script)),
        vclock_(vclock),
        controls_(engine),
        look_(controls_.mutable_look()),
        texture_(window.renderer()),
        hud_(engine.manifest()) {
    hud_.show_panel = options.show_hud;
    for (const auto& c : engine.manifest().cameras) shell_count_ = std::max(shell_count_, c.labels.shell + 1);
    hud_.show_help = options.show_help;
    equirect_ = controls_.is_360();
    lattice_ = player::lattice_shape(engine.manifest());
    if (!options.trace.empty()) trace_.emplace(options.trace);
    walkable_ = controls_.mode() == player::ViewMode::lattice;
    if (!options.latency_log.empty()) latency_.log_to(options.latency_log);
  }

  WindowResult run();

 private:
  double now() const { return options_.virtual_time ? vclock_.now() : wall_seconds() - t0_; }
  void run_due_script_commands();
  void handle_event(const SDL_Event& e);
  void do_action(player::Action action);
  void zoom_by(double factor);
  void apply_hud_requests(const HudRequests& req);
  HudInfo gather_hud_info(const player::ShownFrame& shown);
  void draw_value_readout(const player::ShownFrame& shown);
  void refresh_statistics();
  void toggle_recording();
  void save_screenshot(const Image& picture);
  std::filesystem::path output_path(const std::string& stem, const char* ext) const;

  player::Engine& engine_;
  SdlWindow& window_;
  const WindowOptions& options_;
  std::vector<player::ScriptCommand> script_;
  std::size_t next_command_ = 0;
  player::VirtualClock& vclock_;
  player::Controls controls_;
  player::Look& look_;  // controls_'s look: the drag and the wheel turn it
  YuvTexture texture_;
  Hud hud_;
  ViewTransform view_;
  DragRotation drag_;
  Recorder recorder_;
  InputLatency latency_;  // key / click → presented frame, from the input's own timestamp
  FrameLoop loop_;        // which loop iterations draw (nothing is drawn while nothing changes)
  int shell_count_ = 1;
  // The manifest as the engine last re-read it: a database still being written records each new frame's
  // reference there, and the legend and the value readout must scale by it (issue 41.3).
  std::shared_ptr<const store::Manifest> live_manifest_;
  // The value under the cursor of a slice task (issue 41): the pointer in window coordinates, and the
  // readout of the shown (task, frame) kept until either changes.
  int mouse_x_ = 0, mouse_y_ = 0;
  bool mouse_in_ = false;
  player::SliceReadout readout_;
  int readout_task_ = -1, readout_frame_ = -1;
  std::shared_ptr<const store::Manifest> readout_manifest_;  // held: no other manifest can take its address
  std::string readout_text_;
  // Look-around in 360° streams (issue 14): the view (kept by the shared key dispatch, which walks and
  // changes the field of view as every front end does), and the mesh that draws it on the GPU.
  bool equirect_ = false, walkable_ = false;
  std::array<int, 3> lattice_{0, 0, 0};
  std::optional<player::TraceWriter> trace_;
  int trace_step_ = 0;
  void write_trace(const player::ScriptCommand& c);
  /// Shows a refused key's text (player::refusal) and keeps it for the script's trace.
  void refuse(std::string_view why) {
    last_refusal_ = why;
    if (!why.empty()) hud_.notify(std::string(why));
  }
  std::string last_refusal_;
  std::vector<MeshVertex> mesh_;
  std::vector<SDL_Vertex> sdl_mesh_;
  void face_the_action();
  void step_toward_click(int x, int y, bool back);

  double t0_ = wall_seconds();
  bool quit_ = false;
  bool left_down_ = false, right_down_ = false;
  bool screenshot_pending_ = false;
  int shot_counter_ = 0;
  const video::YuvFrame* uploaded_ = nullptr;
  std::shared_ptr<const video::YuvFrame> shown_frame_;  // keeps the uploaded frame alive
  // Window → renderer-output pixel ratio (HiDPI), and sizes of this frame.
  double px_x_ = 1, px_y_ = 1;
  int out_w_ = 1, out_h_ = 1, win_w_ = 1, win_h_ = 1;

  // HUD statistics, refreshed a few times per second (Engine::statistics() copies its sample lists).
  double next_stats_ = 0;
  double display_fps_ = 0, last_present_ = 0;
  player::Statistics stats_;
  double switch_p99_ = 0, input_p99_ = 0;
  // Display-path timings for the end-of-session summary (one double per frame: 0.5 MB per hour at 60 fps).
  std::vector<double> upload_ms_, draw_ms_;
};

// --- script ---
void WindowApp::run_due_script_commands() {
  using Kind = player::ScriptCommand::Kind;
  const double t = now();
  // As headless runs do: the clock's frame first, then the commands due, each traced after its effect.
  if (next_command_ < script_.size() && script_[next_command_].t <= t) engine_.tick();
  while (next_command_ < script_.size() && script_[next_command_].t <= t) {
    const auto& c = script_[next_command_++];
    last_refusal_.clear();
    if (c.kind == Kind::end) {
      quit_ = true;
      continue;
    }
    if (c.kind == Kind::key) {
      // Through SDL's queue, so a scripted key takes exactly the path of a typed one; handled at once so
      // the next command sees its effect.
      if (auto e = key_event_for_name(c.key)) {
        SDL_Event ev = *e;
        ev.key.windowID = SDL_GetWindowID(window_.window());
        ev.key.timestamp = SDL_GetTicks();
        SDL_PushEvent(&ev);
        SDL_Event q;
        while (SDL_PollEvent(&q)) handle_event(q);
      } else {
        do_action(c.action);  // a key name SDL has no key for: apply its action directly
      }
    } else if (!controls_.run(c) && c.kind == Kind::walk) {
      hud_.notify("no camera that way");
    }
    write_trace(c);
  }
}

void WindowApp::write_trace(const player::ScriptCommand& c) {
  if (!trace_) return;
  trace_->write(player::trace_step(trace_step_++, c, engine_, controls_, last_refusal_));
}

// --- actions ---
void WindowApp::zoom_by(double factor) {
  int mx = 0, my = 0;
  const Uint32 focus = SDL_GetWindowFlags(window_.window()) & SDL_WINDOW_MOUSE_FOCUS;
  SDL_GetMouseState(&mx, &my);
  // Around the cursor when it is over the window, else around the centre.
  if (focus)
    view_.zoom_at(factor, mx * px_x_, my * px_y_);
  else
    view_.zoom_at(factor, out_w_ / 2.0, out_h_ / 2.0);
}

// Turns the 360° view toward the strongest signal of the frame on screen (player/face_action.hpp).
void WindowApp::face_the_action() {
  if (!equirect_ || !shown_frame_) {
    refuse(player::refusal(player::Action::face_action, player::ViewMode::sphere));
    return;
  }
  const auto& cam = engine_.manifest().cameras[std::size_t(engine_.selection().camera)];
  const player::ViewBasis basis = player::camera_basis(cam);
  const auto d = player::strongest_signal_direction(*shown_frame_, basis);
  if (!d) {
    refuse(controls_.refusal(player::Action::face_action));
    return;
  }
  look_ = player::look_towards(basis, *d, look_.fov_deg);
  hud_.notify("facing the strongest signal: " + look_text(look_));
}

// Double-click in a walkable 360° database: one step toward the clicked direction (Shift: away from it),
// keeping the world view direction, as a walk key does.
void WindowApp::step_toward_click(int x, int y, bool back) {
  const store::Manifest& m = engine_.manifest();
  const int from = engine_.selection().camera;
  const player::ViewBasis basis = player::camera_basis(m.cameras[std::size_t(from)]);
  const Vec3 d = player::cutout_direction(basis, look_, x * px_x_, y * px_y_, out_w_, out_h_);
  const int to = player::neighbour_toward(m, from, back ? -d : d);
  if (to < 0 || !engine_.jump_to_camera(to)) {
    hud_.notify(back ? "no camera behind that way" : "no camera that way");
    return;
  }
  const Vec3 view = player::look_basis(basis, look_).forward;
  look_ = player::look_towards(player::camera_basis(m.cameras[std::size_t(to)]), view, look_.fov_deg);
  engine_.set_view_direction(view);
}

void WindowApp::do_action(player::Action action) {
  using player::Action;
  if (action == Action::face_action) return face_the_action();
  // One dispatch for every front end (player/controls.hpp): walks, field of view and engine commands.
  switch (controls_.apply(action)) {
    case player::Controls::Result::done:
      if (action == Action::speed_up || action == Action::speed_down || action == Action::speed_reset ||
          action == Action::faster || action == Action::slower) {
        char text[64];
        std::snprintf(text, sizeof text, "speed x%.2f (%.1f frames/s)", engine_.speed(), engine_.speed() * engine_.fps());
        hud_.notify(text);
      }
      return;
    case player::Controls::Result::refused: {
      // The table's and the database's words (player::refusal), the same the browser shows.
      refuse(controls_.refusal(action));
      return;
    }
    case player::Controls::Result::front_end: break;
  }
  switch (action) {
    case Action::zoom_in: zoom_by(1.25); break;
    case Action::zoom_out: zoom_by(0.8); break;
    case Action::zoom_reset: view_.reset(); break;
    case Action::fullscreen: window_.set_fullscreen(!window_.fullscreen()); break;
    case Action::screenshot: screenshot_pending_ = true; break;
    case Action::record: toggle_recording(); break;
    case Action::help: hud_.show_help = !hud_.show_help; break;
    case Action::toggle_hud: hud_.show_panel = !hud_.show_panel; break;
    case Action::quit: quit_ = true; break;
    default: break;
  }
}

// --- events ---
void WindowApp::handle_event(const SDL_Event& e) {
  ImGui_ImplSDL2_ProcessEvent(&e);
  const ImGuiIO& io = ImGui::GetIO();
  switch (e.type) {
    case SDL_QUIT: quit_ = true; break;
    case SDL_WINDOWEVENT:
      if (e.window.event == SDL_WINDOWEVENT_CLOSE && e.window.windowID == SDL_GetWindowID(window_.window())) quit_ = true;
      if (e.window.event == SDL_WINDOWEVENT_LEAVE) mouse_in_ = false;
      break;
    case SDL_KEYDOWN: {
      if (io.WantTextInput) break;
      // Holding a key repeats navigation and frame steps, but not toggles: the table says which.
      if (const player::KeyBinding* b = binding_for_event(e.key); b && !(e.key.repeat && !b->repeats())) do_action(b->action);
      break;
    }
    case SDL_MOUSEBUTTONDOWN:
      if (hud_.covers(float(e.button.x), float(e.button.y))) break;
      if (e.button.button == SDL_BUTTON_LEFT && e.button.clicks == 2 && walkable_) {
        step_toward_click(e.button.x, e.button.y, (SDL_GetModState() & KMOD_SHIFT) != 0);
        break;
      }
      if (e.button.button == SDL_BUTTON_LEFT && equirect_) {
        left_down_ = true;
      } else if (e.button.button == SDL_BUTTON_LEFT) {
        const auto& cam = engine_.manifest().cameras[std::size_t(engine_.selection().camera)];
        drag_.begin(cam.position, cam.up, cam.look_at);
        left_down_ = true;
      } else if (e.button.button == SDL_BUTTON_RIGHT) {
        right_down_ = true;
      }
      break;
    case SDL_MOUSEBUTTONUP:
      if (e.button.button == SDL_BUTTON_LEFT) {
        left_down_ = false;
        drag_.end();
      } else if (e.button.button == SDL_BUTTON_RIGHT) {
        right_down_ = false;
      }
      break;
    case SDL_MOUSEMOTION:
      mouse_x_ = e.motion.x, mouse_y_ = e.motion.y, mouse_in_ = true;  // the value readout follows it
      if (left_down_ && equirect_) {
        // Grab-and-drag: the scene follows the pointer (one output pixel = fov / height degrees).
        const double deg_per_px = look_.fov_deg / std::max(1, out_h_);
        look_.yaw_deg -= e.motion.xrel * px_x_ * deg_per_px;
        look_.pitch_deg += e.motion.yrel * px_y_ * deg_per_px;
        look_ = player::clamped(look_);
      } else if (left_down_ && drag_.active()) {
        drag_.move(e.motion.xrel * px_x_, e.motion.yrel * px_y_, out_h_);
        engine_.snap_to_direction(drag_.direction());
      } else if (right_down_) {
        view_.pan(e.motion.xrel * px_x_, e.motion.yrel * px_y_);
      }
      break;
    case SDL_MOUSEWHEEL:
      if (hud_.covers(float(e.wheel.mouseX), float(e.wheel.mouseY))) break;
      if (equirect_) {  // the wheel narrows / widens the look-around's field of view
        if (e.wheel.preciseY != 0) look_ = player::clamped({look_.yaw_deg, look_.pitch_deg, look_.fov_deg / std::pow(1.15, double(e.wheel.preciseY))});
        break;
      }
      // The event carries the pointer position (SDL >= 2.26), so zoom happens where the wheel turned.
      if (e.wheel.preciseY != 0) view_.zoom_at(std::pow(1.2, double(e.wheel.preciseY)), e.wheel.mouseX * px_x_, e.wheel.mouseY * px_y_);
      break;
    default: break;
  }
}

// --- hud ---
// The value under the cursor when the shown task is a slice (player/value_readout.hpp): read from the
// decoded pixel and the frame's recorded scale, shown beside the pointer. Perspective frames only: in a
// 360° cut-out the window pixel is a resampled mix of frame pixels.
void WindowApp::draw_value_readout(const player::ShownFrame& shown) {
  readout_text_.clear();
  if (equirect_ || !mouse_in_ || !shown_frame_ || shown.status != player::FrameStatus::ok || !live_manifest_) return;
  const store::Manifest& m = *live_manifest_;
  const auto& sel = shown.selection;
  if (m.tasks[std::size_t(sel.task)].method != "slice") return;
  if (hud_.covers(float(mouse_x_), float(mouse_y_))) return;
  double fx = 0, fy = 0;
  view_.window_to_frame(mouse_x_ * px_x_, mouse_y_ * px_y_, fx, fy);
  const int x = int(std::floor(fx)), y = int(std::floor(fy));
  const video::YuvFrame& f = *shown_frame_;
  if (x < 0 || y < 0 || x >= f.width || y >= f.height) return;
  if (sel.task != readout_task_ || sel.frame != readout_frame_ || readout_manifest_ != live_manifest_) {
    readout_ = player::slice_readout(m, sel.task, sel.frame);
    readout_task_ = sel.task, readout_frame_ = sel.frame, readout_manifest_ = live_manifest_;
  }
  if (!readout_.usable) return;
  const auto reading = player::read_pixel(m, readout_, sel.camera, x, y, player::rgb_at(f, x, y));
  readout_text_ = player::reading_text(readout_, reading);
  // Beside the pointer, on the side with room (right and below, else left / above).
  const bool left = mouse_x_ > win_w_ * 0.55, up = mouse_y_ > win_h_ * 0.8;
  ImGui::SetNextWindowPos(ImVec2(float(mouse_x_) + (left ? -16.f : 16.f), float(mouse_y_) + (up ? -16.f : 16.f)),
                          ImGuiCond_Always, ImVec2(left ? 1.f : 0.f, up ? 1.f : 0.f));
  ImGui::SetNextWindowBgAlpha(0.75f);
  constexpr ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                     ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoSavedSettings |
                                     ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav;
  if (ImGui::Begin("##readout", nullptr, flags)) {
    if (reading.kind == player::ValueReading::Kind::none) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.7f, 0.7f, 0.7f, 1));
    ImGui::TextUnformatted(readout_text_.c_str());
    if (reading.kind == player::ValueReading::Kind::none) ImGui::PopStyleColor();
  }
  ImGui::End();
}

void WindowApp::apply_hud_requests(const HudRequests& req) {
  if (req.seek >= 0) engine_.seek(req.seek);
  if (req.jump_camera >= 0) engine_.jump_to_camera(req.jump_camera);
  if (req.toggle_play) engine_.toggle_playing();
}

void WindowApp::refresh_statistics() {
  stats_ = engine_.statistics();
  std::vector<double> lat;
  lat.reserve(stats_.switches.size());
  for (const auto& s : stats_.switches) lat.push_back(s.latency_ms);
  switch_p99_ = player::summarize(std::move(lat)).p99;
  stats_.decode_ms.clear();  // not shown; drop the copy
  std::vector<double> inputs;
  inputs.reserve(latency_.samples().size());
  for (const auto& s : latency_.samples()) inputs.push_back(s.latency_ms);
  input_p99_ = player::summarize(std::move(inputs)).p99;
}

HudInfo WindowApp::gather_hud_info(const player::ShownFrame& shown) {
  HudInfo h;
  live_manifest_ = engine_.live_manifest();
  const store::Manifest& m = *live_manifest_;
  h.manifest = &m;
  h.selection = shown.selection;
  h.frame_count = engine_.frame_count();
  h.sim_time = shown.time;
  h.active_axis = engine_.active_axis();
  h.speed = engine_.speed();
  h.playing = engine_.playing();
  h.loop = engine_.loop();
  h.direction = engine_.direction();
  h.display_fps = display_fps_;
  if (!latency_.samples().empty()) {
    h.have_input_latency = true;
    h.input_latency_ms = latency_.samples().back().latency_ms;
    h.input_latency_p99_ms = input_p99_;
    h.inputs_measured = int(latency_.samples().size());
  }
  if (!stats_.switches.empty()) {
    h.have_switch = true;
    h.last_switch_ms = stats_.switches.back().latency_ms;
    h.last_switch_hit = stats_.switches.back().cache_hit;
    h.switch_p99_ms = switch_p99_;
  }
  h.cache_hits = stats_.cache_hits;
  h.cache_misses = stats_.cache_misses;
  h.cache_bytes = stats_.cache_bytes;
  h.cache_capacity = stats_.cache_capacity;
  h.zoom = view_.zoom();
  h.recording = recorder_.active();
  h.recording_path = recorder_.path();
  h.renderer = window_.renderer_name();
  h.status = shown.status;
  h.shell_count = shell_count_;
  h.status_message = shown.message;
  // The lattice mini-map's arrow: where the viewer looks (the camera's forward outside 360° streams).
  h.view_direction =
      player::look_basis(player::camera_basis(engine_.manifest().cameras[std::size_t(shown.selection.camera)]),
                         equirect_ ? look_ : player::Look{})
          .forward;
  // Inside a 360° stream the camera ahead is the likeliest walk: prefetch it first.
  if (equirect_) engine_.set_view_direction(h.view_direction);
  h.position_label = lattice_position_text(lattice_, shown.selection.camera);
  if (equirect_) {
    h.look_label = (lattice_[0] > 0 ? "" : "360 view   ") + look_text(look_);
    h.half_fov_deg = std::atan(std::tan(look_.fov_deg * M_PI / 360) * double(out_w_) / std::max(1, out_h_)) * 180 / M_PI;
    h.world_label = world_position_text(engine_.manifest().cameras[std::size_t(shown.selection.camera)].position,
                                        h.view_direction, engine_.manifest().domain.up_axis == "z_down");
  }
  if (!m.graph.empty()) {
    const auto& n = m.graph.neighbours[std::size_t(shown.selection.camera)];
    for (int id : {n.left, n.right, n.up, n.down, n.in, n.out})
      if (id >= 0) h.neighbours.push_back(id);
  }
  return h;
}

// --- outputs ---
std::filesystem::path WindowApp::output_path(const std::string& stem, const char* ext) const {
  std::error_code ec;
  std::filesystem::create_directories(options_.output_dir, ec);
  // A new name each time: never overwrite an earlier screenshot or recording.
  for (int i = 0;; ++i) {
    std::string name = stem;
    if (i > 0) name.append("-").append(std::to_string(i));
    name += ext;
    auto p = options_.output_dir / name;
    if (!std::filesystem::exists(p, ec)) return p;
  }
}

void WindowApp::toggle_recording() {
  try {
    if (recorder_.active()) {
      const std::string path = recorder_.path();
      const int n = recorder_.stop(now());
      hud_.notify("recorded " + std::to_string(n) + " frames to " + path);
    } else {
      const auto path = output_path("panoptes-recording-" + time_tag(), ".mp4");
      recorder_.start(path, out_w_, out_h_, engine_.fps(), now());
      hud_.notify("recording to " + path.string() + " (R stops)");
    }
  } catch (const std::exception& ex) {
    hud_.notify(std::string("recording failed: ") + ex.what(), true);
  }
}

void WindowApp::save_screenshot(const Image& picture) {
  const auto sel = engine_.selection();
  char stem[96];
  std::snprintf(stem, sizeof stem, "panoptes-c%d-t%d-f%d", sel.camera, sel.task, sel.frame);
  try {
    const auto path = output_path(stem, ".png");
    write_png(path.string(), picture);
    hud_.notify("screenshot saved to " + path.string());
  } catch (const std::exception& ex) {
    hud_.notify(std::string("screenshot failed: ") + ex.what(), true);
  }
}

// --- frame loop ---
WindowResult WindowApp::run() {
  WindowResult result;
  const double frame_period = 1.0 / engine_.fps();
  bool last = false;
  // Opening the window took time the movie must not have played through (the first frame shown was
  // frame 5 or 16 of the paper's database, not 0): the clock starts now, and again once frame 0 is up.
  engine_.restart_clock();
  while (!last) {
    if (options_.before_frame) options_.before_frame(result.frames_presented);
    const std::size_t commands_before = next_command_;
    run_due_script_commands();
    LoopEvents happened;
    happened.every_frame = options_.virtual_time;
    SDL_Event e;
    // Sleep until input arrives (or playback / the HUD's refresh is due) instead of redrawing an
    // unchanged picture: a key is then handled the moment it comes.
    if (const int wait = options_.virtual_time ? 0 : loop_.wait_ms(engine_.playing(), wall_seconds()); wait > 0) {
      if (SDL_WaitEventTimeout(&e, wait)) {
        latency_.observe(e);
        handle_event(e);
        happened.input = true;
      }
    }
    while (SDL_PollEvent(&e)) {
      latency_.observe(e);
      handle_event(e);
      happened.input = true;
    }
    last = quit_ || (options_.max_frames > 0 && result.frames_presented + 1 >= options_.max_frames);

    engine_.tick();
    const player::ShownFrame shown = engine_.current_frame();
    happened.new_frame = shown.frame.get() != uploaded_;
    happened.busy = last || next_command_ != commands_before || screenshot_pending_ || recorder_.active() ||
                    latency_.pending();
    if (!loop_.should_draw(happened, wall_seconds())) continue;
    if (shown.frame.get() != uploaded_) {
      const auto& f = *shown.frame;
      const int cw = (f.width + 1) / 2;
      const double u0 = wall_seconds();
      texture_.upload({f.width, f.height, f.y.data(), f.u.data(), f.v.data(), f.width, cw, cw});
      upload_ms_.push_back((wall_seconds() - u0) * 1e3);
      uploaded_ = shown.frame.get();
      shown_frame_ = shown.frame;
    }

    window_.output_size(out_w_, out_h_);
    SDL_GetWindowSize(window_.window(), &win_w_, &win_h_);
    px_x_ = win_w_ > 0 ? double(out_w_) / win_w_ : 1;
    px_y_ = win_h_ > 0 ? double(out_h_) / win_h_ : 1;
    view_.set_sizes(out_w_, out_h_, texture_.width(), texture_.height());
    texture_.set_pixelated(view_.scale() >= 3);

    SDL_Renderer* r = window_.renderer();
    SDL_SetRenderDrawColor(r, 16, 17, 20, 255);
    const double draw0 = wall_seconds();
    if (!equirect_) SDL_RenderClear(r);  // a look-around covers every pixel: no clear (a full-window fill on software GL)
    // Where the data is drawn: the fitted, zoomed frame; a look-around fills the window.
    const Rect fr = equirect_ ? Rect{0, 0, double(out_w_), double(out_h_)} : view_.frame_rect();
    if (equirect_) {
      // The perspective cut-out of the 360° frame over the whole window, textured on the GPU.
      const player::ViewBasis cam = player::camera_basis(engine_.manifest().cameras[std::size_t(shown.selection.camera)]);
      build_fitted_look_mesh(cam, look_, 0, 0, float(out_w_), float(out_h_), texture_.width(), mesh_);
      sdl_mesh_.resize(mesh_.size());
      for (std::size_t k = 0; k < mesh_.size(); ++k)
        sdl_mesh_[k] = {{mesh_[k].x, mesh_[k].y}, {255, 255, 255, 255}, {mesh_[k].u, mesh_[k].v}};
      // The mesh samples the frame once converted to RGBA (the conversion is redone only for a new frame).
      SDL_Texture* rgba = texture_.rgba();
      SDL_RenderGeometry(r, rgba ? rgba : texture_.texture(), sdl_mesh_.data(), int(sdl_mesh_.size()), nullptr, 0);
    } else {
      const SDL_FRect dst{float(fr.x), float(fr.y), float(fr.w), float(fr.h)};
      SDL_RenderCopyF(r, texture_.texture(), nullptr, &dst);
    }

    // Screenshots and recordings hold what is shown of the data, without the HUD on top.
    if (screenshot_pending_ || recorder_.due(now())) {
      try {
        Image picture = window_.read_pixels();
        if (screenshot_pending_) save_screenshot(picture);
        if (recorder_.due(now())) {
          if (recorder_.size_matches(picture.width, picture.height)) {
            recorder_.add(std::move(picture), now());
          } else {
            const std::string path = recorder_.path();
            const int n = recorder_.stop();
            hud_.notify("window size changed: recording stopped after " + std::to_string(n) + " frames (" + path + ")",
                        true);
          }
        }
      } catch (const std::exception& ex) {
        std::string what = ex.what();
        if (recorder_.active()) {
          try {
            recorder_.stop();
          } catch (const std::exception& ex2) {
            what += std::string("; ") + ex2.what();
          }
        }
        hud_.notify("capture failed: " + what, true);
      }
      screenshot_pending_ = false;
    }

    const double wall = wall_seconds();
    // Refresh a few times a second, and at once after a switch so its latency shows immediately.
    const bool switched = shown.selection.camera != result.camera || shown.selection.task != result.task;
    if (wall >= next_stats_ || (switched && result.frames_presented > 0)) {
      refresh_statistics();
      next_stats_ = wall + 0.5;
    }
    ImGui::GetIO().FontGlobalScale = Hud::scale_for(float(win_w_), float(win_h_));
    const HudInfo info = gather_hud_info(shown);
    // ImGui draws an auto-sized window only from the frame after the one it (re)appears in, where it
    // measures it: `--max-frames 1 --screenshot-on-exit` held the frame without HUD and legend (also a
    // HUD turned on with I in the last frame). The picture taken on exit gets a pass that only lays
    // the overlay out (nothing drawn, its requests ignored), so every window it holds is measured.
    if (last && !options_.screenshot_on_exit.empty()) {
      window_.begin_imgui_frame();
      hud_.draw(info, float(win_w_), float(win_h_));
      draw_value_readout(shown);
      ImGui::EndFrame();
    }
    window_.begin_imgui_frame();
    const HudRequests req = hud_.draw(info, float(win_w_), float(win_h_));
    draw_value_readout(shown);
    window_.render_imgui();
    apply_hud_requests(req);

    if (last && !options_.screenshot_on_exit.empty()) write_png(options_.screenshot_on_exit.string(), window_.read_pixels());
    window_.present();
    latency_.presented();
    loop_.drawn(wall_seconds());
    draw_ms_.push_back((wall_seconds() - draw0) * 1e3);

    ++result.frames_presented;
    if (result.frames_presented == 1) engine_.restart_clock();  // the first frame's decode and upload
    if (last_present_ > 0) {
      const double dt = wall - last_present_;
      if (dt > 0) display_fps_ = display_fps_ > 0 ? 0.9 * display_fps_ + 0.1 / dt : 1 / dt;
    }
    last_present_ = wall;
    if (options_.virtual_time) vclock_.advance(frame_period);

    result.camera = shown.selection.camera;
    result.task = shown.selection.task;
    result.frame = shown.selection.frame;
    result.zoom = view_.zoom();
    result.view_x = int(std::lround(fr.x));
    result.view_y = int(std::lround(fr.y));
    result.view_w = int(std::lround(fr.w));
    result.view_h = int(std::lround(fr.h));
    result.hud_drawn = hud_.panel_drawn();
    result.window_w = out_w_;
    result.window_h = out_h_;
    result.fullscreen = window_.fullscreen();
    result.notice = hud_.last_notice();
    result.legend = hud_.last_legend();
    result.readout = readout_text_;
    result.help_fits = hud_.help_fits();
    result.status = std::string(player::to_string(shown.status));
  }
  window_.native_size(result.native_w, result.native_h);
  if (recorder_.active()) {
    const std::string path = recorder_.path();
    const int n = recorder_.stop();
    std::fprintf(stderr, "panoptes: recorded %d frames to %s\n", n, path.c_str());
  }

  const player::Statistics st = engine_.statistics();
  std::vector<double> lat;
  int hits = 0;
  for (const auto& s : st.switches) {
    lat.push_back(s.latency_ms);
    hits += s.cache_hit ? 1 : 0;
  }
  const player::Summary sw = player::summarize(lat);
  const player::Summary dec = player::summarize(st.decode_ms);
  const player::Summary up = player::summarize(upload_ms_);
  const player::Summary draw = player::summarize(draw_ms_);
  std::vector<double> inputs;
  int x_timed = 0;
  for (const auto& s : latency_.samples()) {
    inputs.push_back(s.latency_ms);
    x_timed += s.x_server_time ? 1 : 0;
  }
  const player::Summary in = player::summarize(inputs);
  result.inputs_measured = int(in.count);
  result.input_latency_p50_ms = in.p50;
  result.input_latency_p99_ms = in.p99;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "%d window frames; %zu switches (%d prefetched), latency p50 %.2f ms p99 %.2f ms max %.2f ms; "
                "%lld frames decoded, %.2f ms each (p50); cache hits %lld of %lld shown frames; "
                "%zu texture uploads p50 %.2f ms; draw+HUD+present p50 %.2f ms p99 %.2f ms (%s renderer); "
                "input -> presented frame p50 %.1f ms p99 %.1f ms over %zu inputs (%d timed by the X server)",
                result.frames_presented, sw.count, hits, sw.p50, sw.p99, sw.max, (long long)dec.count, dec.p50,
                (long long)st.cache_hits, (long long)st.frames_shown, up.count, up.p50, draw.p50, draw.p99,
                window_.renderer_name().c_str(), in.p50, in.p99, in.count, x_timed);
  result.summary = buf;
  return result;
}

}  // namespace

// --- entry ---
WindowResult run_window(const std::filesystem::path& db, const WindowOptions& options) {
  // The database and script are checked before any window opens, so their errors need no display.
  std::vector<player::ScriptCommand> script;
  if (!options.script.empty()) script = player::read_script(options.script);
  player::VirtualClock vclock;
  player::EngineOptions eo;
  eo.cache_bytes = options.cache_bytes;
  eo.prefetch = options.prefetch;
  eo.start_playing = !options.paused;
  eo.loop = options.loop;
  eo.camera = options.camera;
  eo.task = options.task;
  eo.frame = options.frame;
  if (options.virtual_time) eo.time_source = vclock.source();
  player::Engine engine(db, eo);
  player::check_script(script, engine.manifest());
  // The short-run rule every front end shares (player/playback_rule.hpp).
  engine.set_speed(options.speed > 0 ? options.speed
                                     : player::starting_speed(engine.frame_count(), engine.fps(),
                                                              engine.manifest().playback_fps));

  if (options.before_open_window) options.before_open_window();
  const auto& m = engine.manifest();
  SdlWindowOptions wo;
  wo.title = "Panoptes - " + (m.title.empty() ? db.filename().string() : m.title);
  wo.width = options.width > 0 ? options.width : m.image.width;
  wo.height = options.height > 0 ? options.height : m.image.height;
  // Without an explicit size the window fills most of the display whatever the frame size (a 256-pixel
  // database must not open as a stamp, a 4K one must fit), keeping the frame's aspect.
  if (options.width <= 0 && options.height <= 0) wo.fill_display = 0.85;
  wo.fullscreen = options.fullscreen;
  wo.software_renderer = options.software_renderer;
  wo.vsync = options.vsync;
  SdlWindow window(wo);
  WindowApp app(engine, window, options, std::move(script), vclock);
  return app.run();
}

}  // namespace panoptes::ui
