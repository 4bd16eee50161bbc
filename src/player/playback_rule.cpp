#include "player/playback_rule.hpp"

#include <algorithm>

namespace panoptes::player {

double starting_speed(int frame_count, double fps, double playback_fps) {
  // The eye cannot follow waves that cross the domain in under a second or two; a preferred rate in
  // the manifest is the author's decision and is kept.
  if (playback_fps > 0 || frame_count <= 1 || !(fps > 0)) return 1.0;
  return std::clamp(frame_count / (fps * kShortestRunSeconds), kShortRunSpeedMin, 1.0);
}

}  // namespace panoptes::player
