#include "ui/input_latency.hpp"

// gtest before Xlib: Xlib's macros (None, Bool, ...) break gtest's templates.
#include <gtest/gtest.h>
#include <SDL.h>
#ifdef PANOPTES_HAVE_X11
#include <SDL_syswm.h>
#include <X11/Xlib.h>
#endif

#include <cstdint>

using namespace panoptes::ui;

// X server times are CLOCK_MONOTONIC milliseconds wrapped to 32 bits: converted back by their age,
// also across the wrap; an age that is negative or of more than 10 s means another clock.
TEST(InputLatency, XServerTimesMapToTheMonotonicClock) {
  const double now = 5'000'123.75;  // ms
  EXPECT_NEAR(x_time_to_monotonic(5'000'123, now), 5'000'123.5, 1e-9);  // this very millisecond
  EXPECT_NEAR(x_time_to_monotonic(5'000'083, now), 5'000'083.5, 1e-9);  // 40 ms ago
  // Just past the 32-bit wrap: now = 2^32 + 10 ms, the press 30 ms before it.
  const double wrapped = 4294967296.0 + 10.2;
  EXPECT_NEAR(x_time_to_monotonic(4294967276u, wrapped), 4294967296.0 - 20 + 0.5, 1e-6);
  EXPECT_LT(x_time_to_monotonic(5'000'200, now), 0) << "a time in the future is another clock";
  EXPECT_LT(x_time_to_monotonic(1'000, now), 0) << "83 minutes old: another clock";
}

#ifdef PANOPTES_HAVE_X11
// A key press: the X server's timestamp opens the sample (not SDL's later queue time), the next
// present closes it; a scripted key without an X event falls back to SDL's timestamp.
TEST(InputLatency, MeasuresFromTheXServerTimestampToThePresent) {
  InputLatency lat;
  const double now = monotonic_ms();
  SDL_SysWMmsg msg{};
  msg.subsystem = SDL_SYSWM_X11;
  msg.msg.x11.event.type = KeyPress;
  msg.msg.x11.event.xkey.time = Time(std::uint32_t(std::uint64_t(now) & 0xffffffffu) - 40);  // 40 ms ago
  SDL_Event wm{};
  wm.type = SDL_SYSWMEVENT;
  wm.syswm.msg = &msg;
  lat.observe(wm);
  SDL_Event key{};
  key.type = SDL_KEYDOWN;
  key.key.timestamp = SDL_GetTicks();  // SDL queued it just now
  key.key.keysym.sym = SDLK_UP;
  lat.observe(key);
  EXPECT_TRUE(lat.pending());
  lat.presented();
  EXPECT_FALSE(lat.pending());
  ASSERT_EQ(lat.samples().size(), 1u);
  EXPECT_TRUE(lat.samples()[0].x_server_time);
  EXPECT_NEAR(lat.samples()[0].latency_ms, 40, 2.0) << "from the X server's time, not SDL's";
  EXPECT_EQ(lat.samples()[0].what, "key Up");

  // No X event before it (a scripted key): SDL's own timestamp, 25 ms ago.
  SDL_Event scripted = key;
  const Uint32 t = SDL_GetTicks();
  scripted.key.timestamp = t >= 25 ? t - 25 : 0;
  lat.observe(scripted);
  lat.presented();
  ASSERT_EQ(lat.samples().size(), 2u);
  EXPECT_FALSE(lat.samples()[1].x_server_time);
  if (t >= 25) EXPECT_NEAR(lat.samples()[1].latency_ms, 25, 2.0);
  // Nothing pending: a present adds nothing.
  lat.presented();
  EXPECT_EQ(lat.samples().size(), 2u);
}
#endif
