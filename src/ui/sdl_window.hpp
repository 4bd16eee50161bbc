#pragma once
// RAII ownership of SDL (video subsystem), one window, its 2-D renderer and the Dear ImGui context
// bound to them through the SDL / SDL_Renderer backends.
#include <string>

#include "core/image.hpp"

struct SDL_Window;
struct SDL_Renderer;

namespace panoptes::ui {

/// How to open the window.
struct SdlWindowOptions {
  /// If > 0: scale width x height (up or down, aspect kept) so the window fills this fraction of the
  /// display's usable area in its tighter dimension. Else the size is kept, only shrunk to fit.
  double fill_display = 0;
  std::string title = "Panoptes";
  int width = 960, height = 720;
  bool fullscreen = false;
  bool software_renderer = false;  ///< force SDL's software renderer
  bool vsync = true;
};

/// The window, its renderer and the ImGui context. Only one may exist at a time (ImGui's backends
/// keep global state). Must be used from the thread that created it.
class SdlWindow {
 public:
  /// Initializes SDL video, creates the window and renderer (accelerated if available, else
  /// software), and ImGui. Throws panoptes::Error when there is no display (the message suggests
  /// `--headless` or `xvfb-run`) or when SDL fails (with SDL's reason).
  explicit SdlWindow(const SdlWindowOptions& options);
  ~SdlWindow();
  SdlWindow(const SdlWindow&) = delete;
  SdlWindow& operator=(const SdlWindow&) = delete;

  SDL_Window* window() const { return window_; }
  SDL_Renderer* renderer() const { return renderer_; }
  /// Renderer name as SDL reports it (e.g. "opengl", "software").
  const std::string& renderer_name() const { return renderer_name_; }
  /// Size of the renderer's output in pixels (may differ from the window size on HiDPI screens).
  void output_size(int& w, int& h) const;

  /// Toggles full screen: the desktop full-screen mode where a window manager can grant it; on an X
  /// server without one (Xvfb, bare X) a borderless window over the whole display, since there SDL's
  /// request goes unanswered and the window kept its size while SDL drew for the display's.
  void set_fullscreen(bool on);
  bool fullscreen() const { return fullscreen_; }
  /// The window's size as the windowing system has it (X11: the X server's own geometry), which is
  /// what the user sees; falls back to SDL's window size where that cannot be asked.
  void native_size(int& w, int& h) const;

  /// Starts an ImGui frame (call once per frame, after the events were given to process_event).
  void begin_imgui_frame();
  /// Renders ImGui's draw data with the renderer (before present()).
  void render_imgui();
  /// Reads back what has been rendered so far in this frame (before present()) as RGBA. Throws
  /// panoptes::Error if the renderer cannot read pixels.
  Image read_pixels() const;
  void present();

 private:
  SDL_Window* window_ = nullptr;
  SDL_Renderer* renderer_ = nullptr;
  std::string renderer_name_;
  bool fullscreen_ = false;
  bool emulated_fullscreen_ = false;  ///< full screen as a borderless display-sized window (no WM)
  int windowed_x_ = 0, windowed_y_ = 0, windowed_w_ = 0, windowed_h_ = 0;  ///< restored when leaving it
  bool imgui_sdl_ = false, imgui_renderer_ = false;
};

}  // namespace panoptes::ui
