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
#include "insitu/config.hpp"
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
            const bool on = frames.at(x, y, t)[3] != 0;
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
    const double c1 = cpu_seconds();
    SweepFrames frames;
    render_sweep(cam, fields, tasks, frames);
    const double c2 = cpu_seconds();
    state.counters["grouped_cpu_s"] = c1 - c0;
    state.counters["sweep_cpu_s"] = c2 - c1;
    state.counters["grouped_over_sweep"] = (c1 - c0) / (c2 - c1);
    state.SetIterationTime(c1 - c0);
  }
}
BENCHMARK(BM_SweepGrouped)->ArgName("windows")->Arg(0)->Arg(1)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
