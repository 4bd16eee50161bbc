#pragma once
// The interactive front end: an SDL2 window showing the player engine's current frame (YUV planes
// uploaded to a streaming GPU texture, no CPU colour conversion) under a Dear ImGui HUD.
// `panoptes play DB` (src/app/cmd_play.cpp) calls run_window() unless --headless is given.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>

namespace panoptes::ui {

/// Options of run_window(). Defaults suit an interactive session.
struct WindowOptions {
  /// Initial window size in pixels; 0 x 0 = the frame's aspect filling most (85 %) of the display.
  int width = 0, height = 0;
  bool fullscreen = false;
  /// Use SDL's software renderer even if an accelerated one exists (tests under Xvfb, remote X).
  bool software_renderer = false;
  /// Synchronise presentation with the display's refresh (off: render as fast as possible).
  bool vsync = true;

  /// Where playback starts.
  int camera = 0, task = 0, frame = 0;
  /// Playback speed factor (¼ … 8) and whether playback starts running / loops at the end. 0 = automatic:
  /// ×1 of the database's playback rate, slowed down (to ×¼ at most) when the whole run would last
  /// under 4 s.
  double speed = 0;
  bool paused = false;
  bool loop = true;
  /// Frame cache cap for the engine in bytes; 0 = the engine's default for this machine.
  std::size_t cache_bytes = 0;
  /// Background prefetch of the neighbouring streams (off: every switch decodes on the display path).
  bool prefetch = true;
  /// Run playback and the script on a virtual clock that advances one database frame period per
  /// presented window frame (deterministic: tests, recorded demos). Off: wall-clock time.
  bool virtual_time = false;

  /// A script of timed key presses in the player's script format (e.g. `t=0.5 key=Right`), injected as
  /// if typed: for demos and the window test. Empty = none.
  std::filesystem::path script;
  /// Writes the trace of the script (the state after each command, player/trace.hpp) here. Empty = none.
  std::filesystem::path trace;
  /// Close the window by itself after this many presented frames (0 = run until the user closes it).
  int max_frames = 0;
  /// When closing, save the window's final rendered image (frame + HUD) as PNG here. Empty = none.
  std::filesystem::path screenshot_on_exit;
  /// Directory for screenshots taken with S and recordings made with R (default: current directory).
  std::filesystem::path output_dir = ".";
  /// Show the HUD at start (key I toggles it; H / F1 toggle the help overlay).
  bool show_hud = true;
  /// Show the help overlay at start.
  bool show_help = false;
  /// Called at the start of every window frame with the number of frames presented so far, before
  /// the frame's events are polled: tests push synthetic SDL mouse events here. Empty = none.
  std::function<void(int)> before_frame;
  /// Called once after the database is opened and before the window opens (tests: a slow start).
  std::function<void()> before_open_window;
  /// Write every measured input → presented-frame latency here, one line each (monotonic clock, ms):
  /// what desktop_latency_bench compares with pixels watched from outside. Empty = none.
  std::filesystem::path latency_log;
};

/// What the session ended with (for tests and for the command to print a summary).
struct WindowResult {
  /// Window frames drawn and presented. With wall-clock time the window draws only when something
  /// changed (and twice a second for the HUD), so this counts drawings, not elapsed display refreshes.
  int frames_presented = 0;
  int camera = -1, task = -1;   ///< selection shown last
  int frame = -1;               ///< database frame shown last
  double zoom = 1.0;            ///< magnification at exit (1 = whole frame fitted to the window)
  int view_x = 0, view_y = 0, view_w = 0, view_h = 0;  ///< where the frame was drawn at exit (pixels)
  int window_w = 0, window_h = 0;  ///< the window's drawing area at exit (pixels)
  int native_w = 0, native_h = 0;  ///< the window's size at exit as the windowing system has it
  bool fullscreen = false;         ///< in full screen at exit
  std::string notice;              ///< the last notice the HUD showed (why a key did nothing, ...)
  std::string legend;              ///< the colour legend's ranges as last drawn ("0 .. 2.41e-03 1/s"; bars joined by "; ")
  std::string readout;             ///< the value readout beside the pointer as last drawn (slice tasks; empty: none)
  bool hud_drawn = false;       ///< the HUD window was submitted to ImGui in the last frame
  bool help_fits = false;       ///< the help overlay, when last drawn, showed every line without scrolling
  std::string status = "ok";    ///< health of the frame shown last: "ok", "missing", "unreadable"
  std::string summary;          ///< one-paragraph statistics (switch latency, fps, cache hits)
  int inputs_measured = 0;      ///< keys, clicks and wheel turns whose latency to the screen was measured
  double input_latency_p50_ms = 0, input_latency_p99_ms = 0;  ///< input's own timestamp → frame presented
};

/// Opens the database at `db`, shows it in a window and runs until the user closes the window (or
/// max_frames is reached). Throws panoptes::FileError if db is not a database or is empty, and
/// panoptes::Error if no display is available (message suggests `--headless` or `xvfb-run`).
WindowResult run_window(const std::filesystem::path& db, const WindowOptions& options = {});

}  // namespace panoptes::ui
