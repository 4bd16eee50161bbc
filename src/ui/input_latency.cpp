#include "ui/input_latency.hpp"

#include <SDL.h>
#ifdef PANOPTES_HAVE_X11
#include <SDL_syswm.h>
#include <X11/Xlib.h>
#endif

#include <algorithm>
#include <cmath>
#include <ctime>

#include "core/error.hpp"

namespace panoptes::ui {

double monotonic_ms() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) / 1e6;
}

double x_time_to_monotonic(std::uint32_t x_time, double now_ms, double max_age_ms) {
  // The server's clock is CLOCK_MONOTONIC in whole milliseconds, wrapped to 32 bits: the age is the
  // wrapped difference. A foreign clock gives an arbitrary age, almost never within max_age_ms.
  const auto now32 = std::uint32_t(std::uint64_t(now_ms) & 0xffffffffu);
  const std::int32_t age = std::int32_t(now32 - x_time);
  // The server truncates to whole ms, as does now32: an event of this very millisecond has age 0.
  if (age < 0 || double(age) > max_age_ms) return -1;
  // The press happened within that millisecond: its middle, never later than now.
  return std::min(now_ms, std::floor(now_ms) - double(age) + 0.5);
}

InputLatency::InputLatency() {
#ifdef PANOPTES_HAVE_X11
  SDL_EventState(SDL_SYSWMEVENT, SDL_ENABLE);
#endif
}

InputLatency::~InputLatency() {
  if (log_) std::fclose(log_);
}

void InputLatency::observe(const SDL_Event& e) {
  const double now = monotonic_ms();
  // SDL's timestamp (SDL_GetTicks at queueing) as an age relative to now.
  auto sdl_time = [&](Uint32 ts) { return now - double(std::int32_t(SDL_GetTicks() - ts)); };
  auto open = [&](Uint32 ts, std::string what) {
    const bool x = x_press_ms_ >= 0;
    pending_.push_back({x ? x_press_ms_ : sdl_time(ts), x, std::move(what)});
    x_press_ms_ = -1;
  };
  switch (e.type) {
#ifdef PANOPTES_HAVE_X11
    case SDL_SYSWMEVENT:
      if (e.syswm.msg && e.syswm.msg->subsystem == SDL_SYSWM_X11) {
        const XEvent& xe = e.syswm.msg->msg.x11.event;
        if (xe.type == KeyPress) x_press_ms_ = x_time_to_monotonic(std::uint32_t(xe.xkey.time), now);
        if (xe.type == ButtonPress) x_press_ms_ = x_time_to_monotonic(std::uint32_t(xe.xbutton.time), now);
      }
      break;
#endif
    case SDL_KEYDOWN: open(e.key.timestamp, std::string("key ") + SDL_GetKeyName(e.key.keysym.sym)); break;
    case SDL_MOUSEBUTTONDOWN: open(e.button.timestamp, "button " + std::to_string(int(e.button.button))); break;
    case SDL_MOUSEWHEEL: open(e.wheel.timestamp, "wheel"); break;
    case SDL_KEYUP:
    case SDL_MOUSEBUTTONUP: x_press_ms_ = -1; break;  // a press SDL did not turn into an event of its own
    default: break;
  }
}

void InputLatency::presented() {
  if (pending_.empty()) return;
  const double now = monotonic_ms();
  for (auto& p : pending_) {
    LatencySample s{p.input_ms, now, now - p.input_ms, p.x_time, std::move(p.what)};
    if (log_) {
      std::fprintf(log_, "%.3f\t%.3f\t%.3f\t%s\t%s\n", s.input_ms, s.present_ms, s.latency_ms,
                   s.x_server_time ? "x_server" : "sdl_queue", s.what.c_str());
      std::fflush(log_);
    }
    samples_.push_back(std::move(s));
  }
  pending_.clear();
}

void InputLatency::log_to(const std::filesystem::path& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw FileError(path.string(), "cannot open the latency log for writing");
  if (log_) std::fclose(log_);
  log_ = f;
  std::fprintf(log_, "# input_ms\tpresent_ms\tlatency_ms\tsource\twhat (monotonic clock, ms)\n");
}

}  // namespace panoptes::ui
