#pragma once
// What the in-situ MPI test programs share: the PSNR of two frames and the rank-independence check of
// databases written by the same run on different numbers of ranks (each frame >= 45 dB of the first's).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "store/database.hpp"

namespace panoptes::insitu_test {

inline double frame_psnr(const Image& a, const Image& b) {
  double se = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    const double d = double(a.pixels[i]) - double(b.pixels[i]);
    se += d * d;
    ++n;
  }
  return se == 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 / (se / double(n)));
}

/// 0 when every database is complete with the first's frames and tasks, and every frame is within
/// 45 dB of the first database's; else 1, naming each low frame. `what` labels the printed summary.
inline int compare_databases(const std::vector<std::string>& dirs, const char* what) {
  const store::Database first = store::Database::open(dirs[0]);
  double worst = INFINITY;
  for (const std::string& d : dirs) {
    const store::Database db = store::Database::open(d);
    if (db.status() != store::Status::complete || db.frame_count() != first.frame_count() ||
        db.task_count() != first.task_count()) {
      std::fprintf(stderr, "%s: not complete, or %d frames / %d tasks where %s has %d / %d\n", d.c_str(),
                   db.frame_count(), db.task_count(), dirs[0].c_str(), first.frame_count(), first.task_count());
      return 1;
    }
    for (int c = 0; c < db.camera_count(); ++c)
      for (int t = 0; t < db.task_count(); ++t) {
        auto r0 = first.stream(c, t);
        auto r1 = db.stream(c, t);
        for (int f = 0; f < db.frame_count(); ++f) {
          const double p = frame_psnr(r0->read_rgba(f), r1->read_rgba(f));
          if (p < 45)
            std::fprintf(stderr, "%s: camera %d task %d frame %d at %.1f dB of %s\n", d.c_str(), c, t, f, p,
                         dirs[0].c_str());
          worst = std::min(worst, p);
        }
      }
  }
  std::printf("%s: worst PSNR between %zu databases %.1f dB\n", what, dirs.size(), worst);
  return worst >= 45 ? 0 : 1;
}

}  // namespace panoptes::insitu_test
