#pragma once
// Ray–box intersection in index space, shared by the march's ray set-up (renderer.cpp) and the sweep's
// (sweep.cpp), so both enter and leave bricks on exactly the same planes.
#include <algorithm>
#include <cmath>
#include <utility>

namespace panoptes::render {

/// Intersects the ray O + t·D with the box [lo, hi]; returns false when the ray misses. `axis`
/// receives the axis of the plane where the ray enters (-1 when t0 stays −∞); that plane is lo[axis]
/// when D[axis] > 0, else hi[axis], and t0 is exactly (plane − O[axis]) / D[axis].
inline bool ray_box(const double O[3], const double D[3], const double lo[3], const double hi[3], double& t0, double& t1,
                    int& axis) {
  t0 = -INFINITY;
  t1 = INFINITY;
  axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (D[a] == 0) {
      if (O[a] < lo[a] || O[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - O[a]) / D[a], tb = (hi[a] - O[a]) / D[a];
    if (ta > tb) std::swap(ta, tb);
    if (t0 < ta) t0 = ta, axis = a;  // the value of std::max(t0, ta)
    t1 = std::min(t1, tb);
  }
  return t1 >= t0;
}

}  // namespace panoptes::render
