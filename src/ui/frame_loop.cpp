#include "ui/frame_loop.hpp"

#include <algorithm>
#include <cmath>

namespace panoptes::ui {

bool FrameLoop::should_draw(const LoopEvents& e, double now) {
  if (e.every_frame) return true;
  if (e.input || e.new_frame || e.busy) {
    settle_ = 1;  // ImGui sizes auto-resized windows from the previous frame's contents
    return true;
  }
  if (settle_ > 0) {
    --settle_;
    return true;
  }
  return now - last_draw_ >= kIdleRefresh;
}

int FrameLoop::wait_ms(bool playing, double now) const {
  if (settle_ > 0) return 0;
  const double until_refresh = kIdleRefresh - (now - last_draw_);
  const int idle = std::max(1, int(std::ceil(until_refresh * 1e3)));
  return playing ? std::min(kPlayingPoll, idle) : idle;
}

}  // namespace panoptes::ui
