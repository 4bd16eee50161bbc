#pragma once
// Honest input → screen latency for the window's HUD (issue 30.3): from the input event's own
// timestamp to just after the frame that shows its effect has been presented.
//
// The input's time is the X server's timestamp of the key press / button press (read from SDL's
// system window-manager events), converted to this machine's monotonic clock: that is when the key
// reached the display server, before it waited in the X socket and in SDL's queue for the player's
// loop to look. SDL's own event timestamp is only the moment SDL pumped the event (at the start of a
// loop iteration), which would hide everything the event waited for. Where the X server does not share
// this machine's clock (a remote display) or the event did not come from X (a scripted key), SDL's
// timestamp is used and the sample says so.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

union SDL_Event;

namespace panoptes::ui {

/// Milliseconds on the monotonic clock (CLOCK_MONOTONIC, which a local X server also stamps with).
double monotonic_ms();

/// The monotonic time of an X server timestamp `x_time` (32-bit milliseconds, wrapping), given the
/// monotonic time `now_ms` at which it is read: `now_ms` minus the event's age. Returns a negative
/// value when the age is not plausible (negative, or more than `max_age_ms`): the server's clock is not
/// this machine's monotonic clock.
double x_time_to_monotonic(std::uint32_t x_time, double now_ms, double max_age_ms = 10000);

/// One measured input.
struct LatencySample {
  double input_ms = 0;    ///< when the input happened (monotonic ms)
  double present_ms = 0;  ///< when the frame showing it had been presented (monotonic ms)
  double latency_ms = 0;  ///< present_ms - input_ms
  bool x_server_time = false;  ///< input_ms is the X server's own timestamp (else SDL's queue time)
  std::string what;       ///< "key Up", "button 1", "wheel"
};

/// Collects input events and closes them at the next present. Construct after SDL video is
/// initialised (it turns SDL's system window-manager events on to see the X timestamps).
class InputLatency {
 public:
  InputLatency();
  ~InputLatency();
  InputLatency(const InputLatency&) = delete;
  InputLatency& operator=(const InputLatency&) = delete;

  /// Look at every SDL event before it is handled. Key presses (not auto-repeats), mouse button
  /// presses and wheel turns open a sample.
  void observe(const SDL_Event& event);
  /// True when inputs wait for a present.
  bool pending() const { return !pending_.empty(); }
  /// Call right after the frame was presented: every pending input gets this time as its end.
  void presented();
  /// Writes one line per sample to `path` (input_ms present_ms latency_ms source what); throws
  /// panoptes::FileError if it cannot be opened.
  void log_to(const std::filesystem::path& path);

  const std::vector<LatencySample>& samples() const { return samples_; }

 private:
  struct Pending {
    double input_ms;
    bool x_time;
    std::string what;
  };
  std::vector<Pending> pending_;
  std::vector<LatencySample> samples_;
  // The X server time of the last KeyPress / ButtonPress seen in a system event, waiting for the SDL
  // event SDL makes of it (SDL posts the system event first).
  double x_press_ms_ = -1;
  std::FILE* log_ = nullptr;
};

}  // namespace panoptes::ui
