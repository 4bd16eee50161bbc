// The paper's million movies (issue 46), written and read on this machine. Run by bench/million_bench
// (scripts/bench), which lays the figures out beside the one-file-per-stream layout.
//
//   million_db write DIR CAMERAS PARAMS WxH SNAPSHOTS LAYOUT
//       CAMERAS (Fibonacci rig) x PARAMS (one isosurface task sweeping PARAMS isovalues) streams
//       written through insitu::Session, as a simulation would: a 32^3 dense wave field that
//       changes every snapshot; LAYOUT = packed | files. Prints: wall s, CPU s, peak RSS MB.
//   million_db open DIR        opens the database as `panoptes play` does (player::Engine): ms, RSS MiB
//   million_db first DIR N     N streams at random, each with the database's movie files evicted
//                              from the page cache first: open + decode frame 0, ms (median, max)
//   million_db switch DIR      5 s of 30 fps playback switching camera every 5 frames: switch p50,
//                              p99, max ms (player::Engine statistics) and the hit rate
#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "insitu/session.hpp"
#include "player/engine.hpp"
#include "render/synthetic_fields.hpp"
#include "store/database.hpp"
#include "video/movie_reader.hpp"

using namespace panoptes;
namespace fs = std::filesystem;

namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

double cpu_s() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

double rss_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return double(resident) * double(::sysconf(_SC_PAGE_SIZE)) / (1024.0 * 1024.0);
}

int write(const std::string& dir, int cameras, int params, int w, int h, int snapshots, const std::string& layout) {
  std::string iso = "isovalues = [";
  for (int k = 0; k < params; ++k) {
    char v[32];
    std::snprintf(v, sizeof v, "%s%.6f", k ? ", " : "", 0.05 + 0.9 * (k + 0.5) / params);
    iso += v;
  }
  iso += "]\n";
  const std::string text = "[output]\ntitle = \"million streams\"\nmode = \"overwrite\"\nlayout = \"" + layout +
                           "\"\n[image]\nwidth = " + std::to_string(w) + "\nheight = " + std::to_string(h) +
                           "\n[rig]\nspec = \"fibonacci:" + std::to_string(cameras) +
                           "\"\n[schedule]\nevery_steps = 1\n[video]\ncrf = 28\n"
                           "[[task]]\nname = \"p\"\ntype = \"isosurface\"\nfield = \"p\"\nrelative = true\n" + iso;
  insitu::SessionConfig cfg = insitu::parse_session_config_text(text, "million_db");
  cfg.output_dir = dir;
  const render::GridGeometry g{{32, 32, 32}, {0, 0, 0}, {1, 1, 1}};
  const double t0 = now_s(), c0 = cpu_s();
  insitu::Session session(cfg, g, insitu::LocalBlock::whole(g));
  for (int s = 0; s < snapshots; ++s) {
    // A field that changes from snapshot to snapshot: the dense scene, scaled and shifted in time.
    render::DenseWaveScene scene = render::dense_wave_scene(g);
    const float gain = 1.0f + 0.25f * float(s);
    for (float& v : scene.p) v *= gain;
    session.process(s, double(s), {{"p", scene.p.data(), insitu::ScalarType::f32, {0, 0, 0}}});
    std::fprintf(stderr, "million_db: snapshot %d of %d written (%.0f s)\n", s + 1, snapshots, now_s() - t0);
  }
  session.finalize();
  std::printf("%.2f %.2f %.1f\n", now_s() - t0, cpu_s() - c0, peak_rss_mb());
  return 0;
}

int open(const std::string& dir) {
  const double t0 = now_s();
  player::Engine engine{fs::path(dir)};
  const double ms = (now_s() - t0) * 1e3;
  std::ifstream status("/proc/self/status");
  double hwm_kib = 0;
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) hwm_kib = std::stod(line.substr(6));
  std::printf("%.3f %.2f %.2f %d\n", ms, rss_mib(), hwm_kib / 1024.0, engine.frame_count());
  return 0;
}

// Drops the database's movie bytes from the page cache, so the next read comes from the disk.
void evict(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const int fd = ::open(e.path().c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) continue;
    ::fdatasync(fd);
    ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
    ::close(fd);
  }
}

int first(const std::string& dir, int n) {
  const store::Database db = store::Database::open(dir);
  std::mt19937 rng(46);
  std::vector<double> ms;
  video::YuvFrame frame;
  for (int i = 0; i < n; ++i) {
    const int c = int(rng() % unsigned(db.camera_count())), t = int(rng() % unsigned(db.task_count()));
    evict(dir);
    const double t0 = now_s();
    auto reader = db.stream(c, t);
    reader->read(0, frame);
    ms.push_back((now_s() - t0) * 1e3);
  }
  std::sort(ms.begin(), ms.end());
  std::printf("%.2f %.2f\n", ms[ms.size() / 2], ms.back());
  return 0;
}

int switching(const std::string& dir) {
  player::EngineOptions o;
  o.prefetch = true;
  o.prefetch_threads = 2;
  player::Engine engine(fs::path(dir), o);
  engine.current_frame();
  const double start = now_s();
  for (int k = 0; k < 150; ++k) {
    const double wait = start + k / 30.0 - now_s();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    engine.tick();
    if (k % 5 == 2) engine.apply((k / 5) % 3 == 2 ? player::Action::camera_left : player::Action::camera_right);
    engine.current_frame();
  }
  std::vector<double> lat;
  int hits = 0;
  for (const auto& s : engine.statistics().switches) lat.push_back(s.latency_ms), hits += s.cache_hit;
  if (lat.empty()) throw Error("million_db switch: no switch was recorded");
  std::sort(lat.begin(), lat.end());
  const auto pct = [&](double q) { return lat[std::min(lat.size() - 1, std::size_t(q * double(lat.size() - 1) + 0.5))]; };
  std::printf("%.2f %.2f %.2f %.0f %zu\n", pct(0.5), pct(0.99), lat.back(), 100.0 * hits / double(lat.size()), lat.size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && argc == 8) {
      int w = 0, h = 0;
      if (std::sscanf(argv[5], "%dx%d", &w, &h) != 2) throw Error(std::string("million_db: size ") + argv[5] + "; expected WxH");
      return write(argv[2], std::atoi(argv[3]), std::atoi(argv[4]), w, h, std::atoi(argv[6]), argv[7]);
    }
    if (mode == "open" && argc == 3) return open(argv[2]);
    if (mode == "first" && argc == 4) return first(argv[2], std::atoi(argv[3]));
    if (mode == "switch" && argc == 3) return switching(argv[2]);
    std::fprintf(stderr,
                 "usage: million_db write DIR CAMERAS PARAMS WxH SNAPSHOTS packed|files\n"
                 "       million_db open DIR | first DIR N | switch DIR\n");
    return mode == "--help" ? 0 : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "million_db: %s\n", e.what());
    return 1;
  }
}
