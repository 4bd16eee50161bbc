#pragma once
// The speed rules every front end shares (window, headless, export-path, Python, and the browser via
// keys.json): the speed range, the key steps and the short-run rule, by which a database without a
// preferred playback rate whose whole run would flash by at its video rate starts slower.
namespace panoptes::player {

inline constexpr double kSpeedMin = 0.25, kSpeedMax = 8;
/// `>` / `<` multiply / divide the speed by this; `]` / `[` by kFineSpeedFactor (as mpv).
inline constexpr double kFasterFactor = 2, kFineSpeedFactor = 1.1;
/// The short-run rule: a run shorter than this many seconds at ×1 starts slowed down, ...
inline constexpr double kShortestRunSeconds = 4;
/// ... but never below this speed.
inline constexpr double kShortRunSpeedMin = 0.25;

/// The starting speed of a database with `frame_count` frames at `fps` frames per second (×1) and the
/// manifest's `playback_fps` (≤ 0: none recorded): clamp(frames ÷ (fps · 4 s), ¼, 1) without a
/// playback rate and with more than one frame, else 1. E.g. 24 frames at 30 fps: ×¼ (3.2 s).
double starting_speed(int frame_count, double fps, double playback_fps);

}  // namespace panoptes::player
