// Issue 45, point 2: a thousand parameters per camera. Side by side in one run:
//   BM_IsoSweep       one isosurface vs the 1,000-value isovalue sweep (render_sweep(), one march per
//                     ray for all values), 4 cameras at 230x224, and the per-frame PSNR of the sweep's
//                     frames against rendering each of a sample of its values alone (render_brick()).
//   BM_WindowSweep    the same for one volume task vs a 1,000-window transfer-function sweep.
//   BM_SweepGrouped   the sweeps as render_brick() renders them (groups of 64 tasks per march), one
//                     camera: the path before render_sweep(), for the before/after ratio.
//   BM_SessionSweep   1,000 parameters x 8 cameras x 460x448 through the in-situ Session (render,
//                     finish, encode, write), one snapshot, in a child process: its peak resident
//                     memory (getrusage ru_maxrss of the child) and CPU seconds, and bytes per stream.
// The scene is the ParaView anchor's: render::dense_wave_scene on 128x256x80 points, field p (spacing
// 1); cameras of the Yin-Yang rig around the domain. ref = the 99.9th percentile of |p|.
//   Isovalues: 1,000 evenly spaced in [-0.9, 0.9] x ref. Windows: preset "hot" over
//   [a, a + 0.25] x ref for 1,000 values of a evenly spaced in [0, 0.75].
// "One" = the median CPU time of the sampled parameters rendered alone (every 125th parameter: 8
// of them, indices 62, 187, ..., 937), each rendered by render_brick() with the library's defaults
// (no adaptive sampling, no isosurface anti-aliasing: what render_sweep() computes).
#include <benchmark/benchmark.h>
#include <omp.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "core/memory.hpp"
#include "insitu/config.hpp"
#include "insitu/resources.hpp"
#include "insitu/session.hpp"
#include "render/renderer.hpp"
#include "render/sweep.hpp"
#include "render/synthetic_fields.hpp"

extern char** environ;

using namespace panoptes;
using namespace panoptes::render;

namespace {

constexpr int kParams = 1000;
constexpr int kSampleEvery = 125;  // the parameters rendered alone for the reference: j = 62 + 125·i
const GridGeometry kGrid{{128, 256, 80}, {0, 0, 0}, {1, 1, 1}};

double cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Scene {
  DenseWaveScene waves = dense_wave_scene(kGrid);
  double ref = abs_percentile(FieldView::whole(kGrid, waves.p.data()), 0.999);
  std::vector<PreparedField> iso_fields, vol_fields;  // without / with the corner copy (as prepare_fields())
  Scene() {
    const FieldView v = FieldView::whole(kGrid, waves.p.data());
    iso_fields.emplace_back(v, MacroCells::kDefaultSize, FieldCopy::none);
    vol_fields.emplace_back(v);
  }
};
const Scene& scene() {
  static const Scene s;
  return s;
}

double iso_value(int j) { return (-0.9 + 1.8 * j / (kParams - 1)) * scene().ref; }
double window_lo(int j) { return 0.75 * j / (kParams - 1); }

std::vector<TaskSpec> iso_tasks() {
  std::vector<TaskSpec> t;
  for (int j = 0; j < kParams; ++j) t.push_back(TaskSpec::isosurface(0, float(iso_value(j))));
  return t;
}
std::vector<TaskSpec> window_tasks() {
  std::vector<TaskSpec> t;
  for (int j = 0; j < kParams; ++j)
    t.push_back(TaskSpec::volume(0, TransferFunction::preset("hot"),
                                 ValueWindow::relative_to(window_lo(j), window_lo(j) + 0.25), scene().ref));
  return t;
}

camera::Camera rig_camera(int id, int w, int h) {
  const camera::Domain domain{kGrid.domain_lo(), kGrid.domain_hi() - kGrid.domain_lo()};
  static const camera::Rig rig = camera::make_rig("yinyang", domain);
  return rig.camera(id, w, h);
}

// One sweep against its sampled parameters alone, camera by camera (alternately, so both see the
// same load): CPU seconds of both, and the PSNR of each sampled frame.
void sweep_vs_one(benchmark::State& state, bool iso) {
  const Scene& sc = scene();
  const std::vector<TaskSpec> tasks = iso ? iso_tasks() : window_tasks();
  const std::vector<PreparedField>& fields = iso ? sc.iso_fields : sc.vol_fields;
  const int cams[4] = {12, 40, 77, 100};
  for (auto _ : state) {
    double cpu_sweep = 0;
    std::vector<double> cpu_one;
    std::vector<double> db;
    SweepFrames frames;
    std::vector<PartialImage> one(1);
    PartialImage part;
    std::uint64_t marched = 0, rays = 0;
    // The frames' buffer is allocated once, as a session keeps it from camera to camera.
    render_sweep(rig_camera(cams[0], 230, 224), fields, tasks, frames);
    for (int c : cams) {
      const camera::Camera cam = rig_camera(c, 230, 224);
      double c0 = cpu_seconds();
      const RenderStats st = render_sweep(cam, fields, tasks, frames);
      cpu_sweep += cpu_seconds() - c0;
      marched += st.marched_samples, rays += st.rays;
      for (int j = kSampleEvery / 2; j < kParams; j += kSampleEvery) {
        c0 = cpu_seconds();
        render_brick(cam, fields, std::span(tasks).subspan(std::size_t(j), 1), one);
        cpu_one.push_back(cpu_seconds() - c0);
        const Image alone = finish_image(one[0], cam, kGrid);
        frames.to_partial(j, part);
        db.push_back(std::min(99.0, psnr(finish_image(part, cam, kGrid), alone)));
        if (std::getenv("SWEEP_BENCH_VERBOSE")) std::fprintf(stderr, "camera %d parameter %d: %.2f dB\n", c, j, db.back());
      }
    }
    // cpu_one holds every sampled parameter once per camera: "one" is the median over parameters of
    // their 4-camera sums.
    const int S = int(cpu_one.size()) / 4;
    std::vector<double> per_param(std::size_t(S), 0.0);
    for (std::size_t i = 0; i < cpu_one.size(); ++i) per_param[i % std::size_t(S)] += cpu_one[i];
    std::sort(per_param.begin(), per_param.end());
    const double one_s = per_param[std::size_t(S / 2)];
    std::sort(db.begin(), db.end());
    {  // hits per ray of the last camera: frames with something at a pixel
      std::uint64_t shown = 0, px = 0;
      for (int y = 0; y < frames.height; ++y)
        for (int x = 0; x < frames.width; ++x) {
          bool any = false;
          for (int t = 0; t < frames.count; ++t) {
            const bool on = frames.shows(x, y, t);
            shown += on, any = any || on;
          }
          px += any;
        }
      state.counters["shown_per_ray"] = double(shown) / double(std::max<std::uint64_t>(px, 1));
    }
    state.counters["sweep_cpu_s"] = cpu_sweep;
    state.counters["one_cpu_s"] = one_s;
    state.counters["sweep_over_one"] = cpu_sweep / one_s;
    state.counters["psnr_min_db"] = db.front();
    state.counters["psnr_median_db"] = db[db.size() / 2];
    state.counters["samples_per_ray"] = double(marched) / double(std::max<std::uint64_t>(rays, 1));
    state.SetIterationTime(cpu_sweep);
  }
}

void BM_IsoSweep(benchmark::State& state) { sweep_vs_one(state, true); }
BENCHMARK(BM_IsoSweep)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
void BM_WindowSweep(benchmark::State& state) { sweep_vs_one(state, false); }
BENCHMARK(BM_WindowSweep)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

// The path before render_sweep(): render_brick() with all 1,000 tasks (16 marches of 64), one camera.
void BM_SweepGrouped(benchmark::State& state) {
  const bool iso = state.range(0) == 0;
  const Scene& sc = scene();
  const std::vector<TaskSpec> tasks = iso ? iso_tasks() : window_tasks();
  const std::vector<PreparedField>& fields = iso ? sc.iso_fields : sc.vol_fields;
  for (auto _ : state) {
    std::vector<PartialImage> out(tasks.size());
    const camera::Camera cam = rig_camera(12, 230, 224);
    const double c0 = cpu_seconds();
    render_brick(cam, fields, tasks, out);
    const double cg = cpu_seconds();
    SweepFrames frames;
    render_sweep(cam, fields, tasks, frames);  // the frames' buffer allocated, as a session keeps it
    const double c1 = cpu_seconds();
    render_sweep(cam, fields, tasks, frames);
    const double c2 = cpu_seconds();
    state.counters["grouped_cpu_s"] = cg - c0;
    state.counters["sweep_cpu_s"] = c2 - c1;
    state.counters["grouped_over_sweep"] = (cg - c0) / (c2 - c1);
    state.SetIterationTime(cg - c0);
  }
}
BENCHMARK(BM_SweepGrouped)->ArgName("windows")->Arg(0)->Arg(1)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

std::int64_t resident_bytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return std::int64_t(resident) * ::sysconf(_SC_PAGESIZE);
}

constexpr int kSessionCameras = 8, kSessionWidth = 460, kSessionHeight = 448;

insitu::SessionConfig session_config(bool iso, const std::string& dir) {
  insitu::SessionConfig cfg;
  cfg.output_dir = dir;
  cfg.mode = insitu::OutputMode::overwrite;
  cfg.keep_interrupted = false;
  cfg.rig = "fibonacci:" + std::to_string(kSessionCameras);
  cfg.width = kSessionWidth, cfg.height = kSessionHeight;
  cfg.video.gop = 1;
  insitu::TaskConfig t;
  t.fields = {"p"};
  if (iso) {
    t.kind = TaskKind::isosurface;
    t.name = "iso";
    t.iso_relative = true;
    for (int j = 0; j < kParams; ++j) t.isovalues.push_back(-0.9 + 1.8 * j / (kParams - 1));
  } else {
    t.kind = TaskKind::volume;
    t.name = "p";
    t.windows.clear();
    for (int j = 0; j < kParams; ++j) t.windows.push_back({window_lo(j), window_lo(j) + 0.25, true});
  }
  cfg.tasks = {t};
  cfg.validate();
  return cfg;
}

// The child: one snapshot of the sweep through a Session; prints "base_rss cpu_s frames estimate".
int session_child(bool iso, const std::string& dir) {
  const DenseWaveScene waves = dense_wave_scene(kGrid);
  const std::int64_t base = resident_bytes();
  const double c0 = cpu_seconds();
  insitu::SessionConfig cfg = session_config(iso, dir);
  const MemoryEstimate e = insitu::estimate_session_memory(cfg, double(kGrid.dims[0]) * kGrid.dims[1] * kGrid.dims[2], kSessionCameras, 1,
                                                           omp_get_max_threads());
  std::fprintf(stderr, "estimate: %s\n", e.describe().c_str());
  insitu::Session session(cfg, kGrid, insitu::LocalBlock::whole(kGrid));
  session.snapshot(0.0, {insitu::FieldInput{"p", waves.p.data(), insitu::ScalarType::f32, {}}});
  session.finalize();
  const insitu::SessionStats st = session.stats();
  std::printf("%lld %.6f %lld %.0f %.6f %.6f\n", (long long)base, cpu_seconds() - c0, (long long)st.frames_encoded,
              e.total(), st.time.render, st.time.encode);
  return 0;
}

// 1,000 parameters x 8 cameras x 460x448 through the Session in a child process (its peak RSS is its own).
void BM_SessionSweep(benchmark::State& state) {
  const bool iso = state.range(0) == 0;
  for (auto _ : state) {
    const std::string dir = (std::filesystem::temp_directory_path() / ("panoptes_sweep_bench_" + std::to_string(::getpid()))).string();
    char self[4096];
    const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) throw Error("sweep_bench: cannot find its own executable");
    self[n] = 0;
    const std::string out = dir + ".out";
    std::string arg = std::string("--session-child=") + (iso ? "iso" : "window") + ":" + dir;
    char* argv[] = {self, arg.data(), nullptr};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    if (posix_spawn(&pid, self, &fa, nullptr, argv, environ) != 0) throw Error("sweep_bench: cannot start the child");
    posix_spawn_file_actions_destroy(&fa);
    int status = 0;
    rusage ru{};
    ::wait4(pid, &status, 0, &ru);
    long long base = 0, frames = 0;
    double cpu = 0, estimate = 0, render_s = 0, encode_s = 0;
    FILE* f = std::fopen(out.c_str(), "r");
    const bool ok = f && std::fscanf(f, "%lld %lf %lld %lf %lf %lf", &base, &cpu, &frames, &estimate, &render_s, &encode_s) == 6;
    if (f) std::fclose(f);
    std::filesystem::remove_all(dir);
    std::filesystem::remove(out);
    if (!ok || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      state.SkipWithError("the session child failed (see its stderr)");
      return;
    }
    const double peak = double(ru.ru_maxrss) * 1024.0;
    const double streams = double(kSessionCameras) * kParams;
    state.counters["peak_rss_GB"] = peak / 1e9;
    state.counters["scene_rss_GB"] = double(base) / 1e9;
    state.counters["estimate_GB"] = estimate / 1e9;
    state.counters["bytes_per_stream"] = (peak - double(base)) / streams;
    state.counters["session_cpu_s"] = cpu;
    state.counters["render_s"] = render_s;
    state.counters["finish_encode_s"] = encode_s;
    state.counters["frames"] = double(frames);
    state.SetIterationTime(cpu);
  }
}
BENCHMARK(BM_SessionSweep)->ArgName("windows")->Arg(0)->Arg(1)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--session-child=", 16) == 0) {
      const std::string a = argv[i] + 16;
      const std::size_t colon = a.find(':');
      try {
        return session_child(a.substr(0, colon) == "iso", a.substr(colon + 1));
      } catch (const std::exception& e) {
        std::fprintf(stderr, "sweep_bench session child: %s\n", e.what());
        return 1;
      }
    }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
