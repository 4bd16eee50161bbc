#pragma once
// How the OpenMP threads of one frame share its tiles (render_brick()). Tiles handed out one at a
// time put neighbouring tiles on different threads. The rays of neighbouring tiles read overlapping
// parts of the volume, and each core's cache then sees only every other tile of it. On the ParaView
// anchor (920×896, 2 threads) one tile per hand-out cost 0.107 CPU-s per image, 8 tiles 0.092, a
// row of tiles 0.089, and one thread alone 0.085. At 928 pixels wide, where a tile's depths fill whole
// cache lines, the costs were the same, so it is not false sharing of the output (docs/rendering.md,
// Round 16). The images do not change: tiles are independent.
#include <algorithm>

namespace panoptes::render {

/// Tiles per OpenMP hand-out for a frame of `tiles` tiles in rows of `row` tiles, on `threads`
/// threads: a whole row of tiles while every thread still gets at least 16 hand-outs (load balance
/// at the frame's end), fewer down to 1 for many threads on a small frame.
inline int tile_chunk(int row, int tiles, int threads) {
  const int balanced = tiles / (16 * std::max(1, threads));
  return std::max(1, std::min(row, balanced));
}

}  // namespace panoptes::render
