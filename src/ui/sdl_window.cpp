#include "ui/sdl_window.hpp"

#include <SDL.h>
#include <imgui.h>
#ifdef PANOPTES_HAVE_X11
#include <SDL_syswm.h>
#include <X11/Xlib.h>
#endif

#include <algorithm>
#include <cfloat>
#include <cstdlib>

#include "backends/imgui_impl_sdl.h"
#include "backends/imgui_impl_sdlrenderer.h"
#include "core/error.hpp"

namespace panoptes::ui {
namespace {

std::string no_display_hint() {
  return " (no display available? run `panoptes play --headless ...` for batch use, or start the "
         "window under a virtual display: `xvfb-run -a panoptes play ...`)";
}

#ifdef PANOPTES_HAVE_X11
Display* x11_display(SDL_Window* window, ::Window* xwindow) {
  SDL_SysWMinfo info;
  SDL_VERSION(&info.version);
  if (!SDL_GetWindowWMInfo(window, &info) || info.subsystem != SDL_SYSWM_X11) return nullptr;
  if (xwindow) *xwindow = info.info.x11.window;
  return info.info.x11.display;
}
#endif

// False only where we know no window manager would answer a full-screen request: an X server
// without an EWMH window manager (no _NET_SUPPORTING_WM_CHECK on the root window), such as Xvfb.
bool window_manager_grants_fullscreen(SDL_Window* window) {
#ifdef PANOPTES_HAVE_X11
  Display* d = x11_display(window, nullptr);
  if (!d) return true;
  const Atom check = XInternAtom(d, "_NET_SUPPORTING_WM_CHECK", True);
  if (check == None) return false;
  Atom type = None;
  int format = 0;
  unsigned long items = 0, after = 0;
  unsigned char* data = nullptr;
  const int status = XGetWindowProperty(d, DefaultRootWindow(d), check, 0, 1, False, AnyPropertyType, &type,
                                        &format, &items, &after, &data);
  const bool present = status == Success && data && items == 1;
  if (data) XFree(data);
  return present;
#else
  (void)window;
  return true;
#endif
}

SDL_Renderer* create_renderer(SDL_Window* window, bool software, bool vsync) {
  Uint32 flags = software ? SDL_RENDERER_SOFTWARE : SDL_RENDERER_ACCELERATED;
  if (vsync && !software) flags |= SDL_RENDERER_PRESENTVSYNC;
  SDL_Renderer* r = SDL_CreateRenderer(window, -1, flags);
  // Xvfb and remote X often have no usable GL: fall back to the software renderer.
  if (!r && !software) r = SDL_CreateRenderer(window, -1, SDL_RENDERER_SOFTWARE);
  return r;
}

}  // namespace

SdlWindow::SdlWindow(const SdlWindowOptions& options) {
#if defined(__linux__)
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  const char* driver = std::getenv("SDL_VIDEODRIVER");
  if ((!display || !*display) && (!wayland || !*wayland) && (!driver || !*driver))
    throw Error("cannot open a window: neither DISPLAY nor WAYLAND_DISPLAY is set" + no_display_hint());
#endif
  // Keep the compositor on (SDL disables it by default for fullscreen games), and let the window
  // receive the first click that focuses it (mini-map clicks).
  SDL_SetHint(SDL_HINT_VIDEO_X11_NET_WM_BYPASS_COMPOSITOR, "0");
  SDL_SetHint(SDL_HINT_MOUSE_FOCUS_CLICKTHROUGH, "1");
  if (SDL_Init(SDL_INIT_VIDEO | SDL_INIT_TIMER | SDL_INIT_EVENTS) != 0)
    throw Error(std::string("cannot initialize SDL video: ") + SDL_GetError() + no_display_hint());

  // A database of 4K frames must still open in a window that fits the screen.
  int width = options.width, height = options.height;
  SDL_Rect usable{};
  if (SDL_GetDisplayUsableBounds(0, &usable) == 0 && usable.w > 0 && usable.h > 0) {
    const double fit = std::min(0.95 * usable.w / width, 0.9 * usable.h / height);
    const double fill = options.fill_display > 0
                            ? options.fill_display * std::min(double(usable.w) / width, double(usable.h) / height)
                            : 1.0;
    const double factor = std::min(fill, fit);
    width = std::max(64, int(width * factor));
    height = std::max(64, int(height * factor));
  }
  Uint32 wflags = SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI;
  window_ = SDL_CreateWindow(options.title.c_str(), SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED,
                             width, height, wflags);
  if (!window_) {
    const std::string why = SDL_GetError();
    SDL_Quit();
    throw Error("cannot create a " + std::to_string(width) + "x" + std::to_string(height) +
                " window: " + why + no_display_hint());
  }
  // Full screen is entered once the window exists, by the path that works on this display.
  if (options.fullscreen) set_fullscreen(true);
  renderer_ = create_renderer(window_, options.software_renderer, options.vsync);
  if (!renderer_) {
    const std::string why = SDL_GetError();
    SDL_DestroyWindow(window_);
    SDL_Quit();
    throw Error("cannot create an SDL renderer for the window: " + why);
  }
  SDL_RendererInfo info{};
  if (SDL_GetRendererInfo(renderer_, &info) == 0 && info.name) renderer_name_ = info.name;

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini littered into the user's working directory
  ImGui::StyleColorsDark();
  ImGui::GetStyle().Alpha = 0.92f;
  imgui_sdl_ = ImGui_ImplSDL2_InitForSDLRenderer(window_);
  imgui_renderer_ = imgui_sdl_ && ImGui_ImplSDLRenderer_Init(renderer_);
  if (!imgui_renderer_) {
    if (imgui_sdl_) ImGui_ImplSDL2_Shutdown();
    ImGui::DestroyContext();
    SDL_DestroyRenderer(renderer_);
    SDL_DestroyWindow(window_);
    SDL_Quit();
    throw Error("cannot initialize the Dear ImGui SDL backends");
  }
}

SdlWindow::~SdlWindow() {
  ImGui_ImplSDLRenderer_Shutdown();
  ImGui_ImplSDL2_Shutdown();
  ImGui::DestroyContext();
  SDL_DestroyRenderer(renderer_);
  SDL_DestroyWindow(window_);
  SDL_Quit();
}

void SdlWindow::output_size(int& w, int& h) const {
  if (SDL_GetRendererOutputSize(renderer_, &w, &h) != 0) SDL_GetWindowSize(window_, &w, &h);
}

void SdlWindow::set_fullscreen(bool on) {
  if (on == fullscreen_) return;
  if (on && !window_manager_grants_fullscreen(window_)) {
    // Without a window manager the X server applies a move and resize at once, and SDL then reports
    // the new size, so the renderer and the HUD follow.
    const int display = std::max(0, SDL_GetWindowDisplayIndex(window_));
    SDL_Rect bounds{};
    if (SDL_GetDisplayBounds(display, &bounds) != 0) return;
    SDL_GetWindowPosition(window_, &windowed_x_, &windowed_y_);
    SDL_GetWindowSize(window_, &windowed_w_, &windowed_h_);
    SDL_SetWindowBordered(window_, SDL_FALSE);
    SDL_SetWindowPosition(window_, bounds.x, bounds.y);
    SDL_SetWindowSize(window_, bounds.w, bounds.h);
    emulated_fullscreen_ = true;
    fullscreen_ = true;
    return;
  }
  if (!on && emulated_fullscreen_) {
    SDL_SetWindowSize(window_, windowed_w_, windowed_h_);
    SDL_SetWindowPosition(window_, windowed_x_, windowed_y_);
    SDL_SetWindowBordered(window_, SDL_TRUE);
    emulated_fullscreen_ = false;
    fullscreen_ = false;
    return;
  }
  if (SDL_SetWindowFullscreen(window_, on ? SDL_WINDOW_FULLSCREEN_DESKTOP : 0) == 0) fullscreen_ = on;
}

void SdlWindow::native_size(int& w, int& h) const {
  SDL_GetWindowSize(window_, &w, &h);
#ifdef PANOPTES_HAVE_X11
  ::Window xw = 0;
  if (Display* d = x11_display(window_, &xw)) {
    XSync(d, False);
    XWindowAttributes a{};
    if (XGetWindowAttributes(d, xw, &a)) {
      w = a.width;
      h = a.height;
    }
  }
#endif
}

void SdlWindow::begin_imgui_frame() {
  ImGui_ImplSDLRenderer_NewFrame();
  ImGui_ImplSDL2_NewFrame();
  // Two passes in one window frame (the layout pass before a screenshot on exit) may read the same
  // performance-counter tick: ImGui asserts a positive frame time.
  if (!(ImGui::GetIO().DeltaTime > 0)) ImGui::GetIO().DeltaTime = 1e-6f;
  // The backend keeps reporting the pointer while the window has keyboard focus, even after it left
  // the window (a mini-map tooltip then stayed on screen): no pointer unless it is over this window.
  if (SDL_GetMouseFocus() != window_) ImGui::GetIO().MousePos = ImVec2(-FLT_MAX, -FLT_MAX);
  ImGui::NewFrame();
}

void SdlWindow::render_imgui() {
  ImGui::Render();
  ImGui_ImplSDLRenderer_RenderDrawData(ImGui::GetDrawData());
}

Image SdlWindow::read_pixels() const {
  int w = 0, h = 0;
  output_size(w, h);
  Image img(w, h, 4);
  // RGBA32 is SDL's alias for "bytes R,G,B,A in memory" whatever the endianness, matching Image.
  if (SDL_RenderReadPixels(renderer_, nullptr, SDL_PIXELFORMAT_RGBA32, img.pixels.data(), int(img.stride())) != 0)
    throw Error(std::string("cannot read the window's pixels: ") + SDL_GetError());
  return img;
}

void SdlWindow::present() { SDL_RenderPresent(renderer_); }

}  // namespace panoptes::ui
