#pragma once
// When the window draws (issue 32.5): a frame is drawn and presented only when something on screen can
// have changed — an input or window event, a new database frame, a script command, a capture — plus
// one frame after input for Dear ImGui's auto-sized windows to settle and a slow refresh for the HUD's
// statistics and expiring notices. Between them the loop sleeps in SDL's event wait, so a key is
// handled the moment it arrives instead of queueing behind a redraw of an unchanged picture (on
// software GL a full redraw of a 1360x680 look-around cost 40-80 ms, the whole budget).
namespace panoptes::ui {

/// What happened in one iteration of the window's loop.
struct LoopEvents {
  bool every_frame = false;  ///< draw every iteration (virtual time: tests and demos count frames)
  bool input = false;        ///< SDL events were handled
  bool new_frame = false;    ///< the engine's shown frame changed
  bool busy = false;         ///< a script command ran, a screenshot or recording is pending, closing
};

/// Decides per loop iteration whether to draw, and how long to wait for input before the next one.
class FrameLoop {
 public:
  /// Seconds between redraws while nothing changes (HUD statistics, notices running out).
  static constexpr double kIdleRefresh = 0.5;
  /// Milliseconds between looks at the playback clock while playing (a new frame is drawn within this).
  static constexpr int kPlayingPoll = 4;

  /// True if this iteration draws; call drawn() after presenting.
  bool should_draw(const LoopEvents& e, double now_s);
  void drawn(double now_s) { last_draw_ = now_s; }
  /// How long to wait for an event before the next iteration (0: go on at once).
  int wait_ms(bool playing, double now_s) const;

 private:
  int settle_ = 0;
  double last_draw_ = -1e300;
};

}  // namespace panoptes::ui
