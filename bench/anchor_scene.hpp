#pragma once
// ParaView's anchor scene as paraview_anchor and march_probe render it (issue 45): one definition of its
// cameras, so the probe's A/B figures are those of the program paraview_bench times.
#include <time.h>

#include "camera/camera.hpp"
#include "render/renderer.hpp"

namespace panoptes::bench {

/// Process CPU seconds, all threads (what the benchmarks compare).
inline double process_cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// Anchor camera i of 8: on the diagonals at 1.1x the domain diagonal, 30° view angle, 920x896.
/// `scale` shrinks the image (march_probe's PROBE_SCALE: fewer pixels per voxel).
inline camera::Camera anchor_camera(const render::GridGeometry& g, int i, double scale = 1) {
  const Vec3 ext = g.domain_hi() - g.domain_lo();
  const Vec3 dir = normalize(Vec3{i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 0.6 : -0.6});
  return camera::Camera(g.centre() + dir * (1.1 * norm(ext)), g.centre(), {0, 0, 1}, 30, int(920 * scale),
                        int(896 * scale));
}

}  // namespace panoptes::bench
