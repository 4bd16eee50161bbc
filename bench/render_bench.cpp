// Renderer benchmark on the standard scene: a 256×512×160 float32 grid of expanding spherical wave
// fronts (p and s fields, generated here), 920×896 images, sample distance 0.5 voxel.
//
// Counters:
//   Msamples_s_core  effective samples per second per core: samples along rays inside the volume,
//                    counted whether marched or skipped, / wall time / OpenMP threads (target ≥ 100)
//   Msamples_cpu_s   the same per CPU-second of the process (robust when the machine is shared)
//   marched_pct      share of those samples actually interpolated (the rest was skipped)
//   ms_per_task      wall time per image when K tasks share the camera (one march) or not
//   cam_frames_s     camera-frames per second with the paper's 3 tasks (p, s, p+s) per camera
//   rig130_s_extrap  seconds for one snapshot of the 130-camera Yin-Yang rig, EXTRAPOLATED linearly
//                    from the handful of cameras rendered (4 directions spread over the sphere)
//   cam_frames_cpu_s, rig130_core_s_extrap   the same per CPU-second / in core-seconds
//   Mimage_samples_cpu_s   effective samples × images produced, per CPU-second
#include <benchmark/benchmark.h>
#include <omp.h>

#include <time.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "standard_scene.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

constexpr int kWidth = 920, kHeight = 896;

const bench::StandardScene& scene() { return bench::standard_scene(); }

// n directions spread over the sphere (golden-angle spiral), cameras at 3 bounding radii.
camera::Camera camera_at(int i, int n) {
  const GridGeometry& g = scene().grid;
  const double z = 1 - (2.0 * i + 1) / n, r = std::sqrt(1 - z * z);
  const double phi = i * std::numbers::pi * (3 - std::sqrt(5.0));
  const Vec3 dir{r * std::cos(phi), r * std::sin(phi), z};
  const double R = 0.5 * norm(g.domain_hi() - g.domain_lo());
  const double fov = 2 * std::asin(1.03 / 3.0) * 180 / std::numbers::pi;
  return camera::Camera(g.centre() + dir * (3 * R), g.centre(), {0, 0, 1}, fov, kWidth, kHeight);
}

const camera::Camera kMain = camera::Camera({-600, -700, 450}, {128, 256, 80}, {0, 0, 1}, 40, kWidth, kHeight);

TaskSpec p_task() { return TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1)); }
TaskSpec s_task() { return TaskSpec::volume(1, TransferFunction::preset("s-wave"), ValueWindow::absolute(0, 1)); }
TaskSpec ps_task() {
  return TaskSpec::volume2(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1), 1,
                           TransferFunction::preset("s-wave"), ValueWindow::absolute(0, 1));
}

// K transfer functions of one field: p-wave windows from narrow to wide (a parameter sweep).
std::vector<TaskSpec> sweep(int k) {
  std::vector<TaskSpec> t;
  for (int i = 0; i < k; ++i)
    t.push_back(TaskSpec::volume(0, TransferFunction::preset(i % 2 ? "hot" : "p-wave"),
                                 ValueWindow::absolute(0, 0.6 + 0.1 * i)));
  return t;
}

// CPU time of the whole process (all threads): on a shared machine wall time × threads overstates
// the cores we actually had, so the per-core rate is also reported per CPU-second.
double process_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void report(benchmark::State& state, const RenderStats& total, double seconds, double cpu_seconds) {
  const int threads = omp_get_max_threads();
  state.counters["Msamples_s_core"] = double(total.samples) / seconds / threads / 1e6;
  state.counters["Msamples_cpu_s"] = double(total.samples) / cpu_seconds / 1e6;
  state.counters["marched_pct"] = total.samples ? 100.0 * double(total.marched_samples) / double(total.samples) : 0;
  state.counters["threads"] = threads;
}

RenderStats add(RenderStats a, const RenderStats& b) {
  a.rays += b.rays;
  a.samples += b.samples;
  a.marched_samples += b.marched_samples;
  a.seconds += b.seconds;
  return a;
}

void BM_Volume(benchmark::State& state) {
  const auto& sc = scene();
  RenderOptions opt;
  opt.skip_empty = state.range(0) != 0;
  opt.tile = int(state.range(1));
  const std::vector<TaskSpec> tasks{p_task()};
  std::vector<PartialImage> out(1);
  RenderStats total;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) total = add(total, render_brick(kMain, sc.fields, tasks, out, opt));
  report(state, total, total.seconds, process_cpu_seconds() - cpu0);
}
BENCHMARK(BM_Volume)->ArgNames({"skip", "tile"})->Args({1, 16})->Args({0, 16})->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TasksOneMarch(benchmark::State& state) {
  const auto& sc = scene();
  const auto tasks = sweep(int(state.range(0)));
  std::vector<PartialImage> out(tasks.size());
  RenderStats total;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) total = add(total, render_brick(kMain, sc.fields, tasks, out));
  report(state, total, total.seconds, process_cpu_seconds() - cpu0);
  state.counters["ms_per_task"] = 1e3 * total.seconds / double(state.iterations()) / double(tasks.size());
  state.counters["Mimage_samples_cpu_s"] = state.counters["Msamples_cpu_s"] * double(tasks.size());
}
BENCHMARK(BM_TasksOneMarch)->ArgName("K")->Arg(1)->Arg(3)->Arg(10)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TasksSeparateMarches(benchmark::State& state) {
  const auto& sc = scene();
  const auto tasks = sweep(int(state.range(0)));
  std::vector<PartialImage> out(1);
  RenderStats total;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state)
    for (const TaskSpec& t : tasks) total = add(total, render_brick(kMain, sc.fields, std::span(&t, 1), out));
  report(state, total, total.seconds, process_cpu_seconds() - cpu0);
  state.counters["ms_per_task"] = 1e3 * total.seconds / double(state.iterations()) / double(tasks.size());
  state.counters["Mimage_samples_cpu_s"] = state.counters["Msamples_cpu_s"];
}
BENCHMARK(BM_TasksSeparateMarches)->ArgName("K")->Arg(3)->Arg(10)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The paper's three tasks (p, s, p+s) in one march per camera, plus compositing into the final
// RGBA8 frame with the outline, for a handful of cameras around the sphere.
void BM_PaperTasksRig(benchmark::State& state) {
  const auto& sc = scene();
  const int ncam = int(state.range(0));
  const std::vector<TaskSpec> tasks{p_task(), s_task(), ps_task()};
  std::vector<PartialImage> out(tasks.size());
  RenderStats total;
  double seconds = 0;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    const double t0 = omp_get_wtime();
    for (int c = 0; c < ncam; ++c) {
      const camera::Camera cam = camera_at(c, ncam);
      total = add(total, render_brick(cam, sc.fields, tasks, out));
      for (const PartialImage& o : out) benchmark::DoNotOptimize(finish_image(o, cam, sc.grid));
    }
    seconds += omp_get_wtime() - t0;
  }
  const double cpu = process_cpu_seconds() - cpu0;
  report(state, total, total.seconds, cpu);
  const double cams_per_s = double(ncam) * double(state.iterations()) / seconds;
  state.counters["cam_frames_s"] = cams_per_s;
  state.counters["rig130_s_extrap"] = 130.0 / cams_per_s;
  // Per CPU-second: camera-frames one core renders when it is not shared.
  state.counters["cam_frames_cpu_s"] = double(ncam) * double(state.iterations()) / cpu;
  state.counters["rig130_core_s_extrap"] = 130.0 / state.counters["cam_frames_cpu_s"];
}
BENCHMARK(BM_PaperTasksRig)->ArgName("cameras")->Arg(4)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Isosurface anti-aliasing (RenderOptions::iso_antialias, issue 32): two fronts (p at 0.3, s at 0.3)
// with it off and on, from outside (kMain, 920x896) and from inside the domain (a 1920x960
// equirectangular frame at a point between the sources, the lattice rigs' view). Counter
// cpu_s_frame: process CPU-seconds per frame (robust on a shared machine).
void BM_Isosurfaces(benchmark::State& state) {
  const auto& sc = scene();
  RenderOptions opt;
  opt.iso_antialias = state.range(0) != 0;
  const bool inside = state.range(1) != 0;
  const camera::Camera cam = inside ? camera::Camera({110, 290, 70}, {128, 180, 90}, {0, 0, 1}, 60, 1920, 960,
                                                     camera::Projection::equirectangular)
                                    : kMain;
  const std::vector<TaskSpec> tasks{TaskSpec::isosurface(0, 0.3f, {1, 0.65f, 0.3f}),
                                    TaskSpec::isosurface(1, 0.3f, {0.55f, 0.9f, 0.55f})};
  std::vector<PartialImage> out(tasks.size());
  RenderStats total;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) total = add(total, render_brick(cam, sc.fields, tasks, out, opt));
  const double cpu = process_cpu_seconds() - cpu0;
  report(state, total, total.seconds, cpu);
  state.counters["cpu_s_frame"] = cpu / double(state.iterations());
}
BENCHMARK(BM_Isosurfaces)->ArgNames({"aa", "inside"})->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})
    ->Iterations(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// One task of each kind (render::kTaskKinds, in that order: volume, isosurface, slice, mip) on the
// p field from kMain, one march each: what a kind costs against a volume task (issue 43). The MIP reads
// the float field through every cell whose values reach above its window's low end, and stops a ray
// only where it reaches the window's top; the volume stops where it is opaque. Counter cpu_s_frame:
// process CPU-seconds per frame.
void BM_TaskKinds(benchmark::State& state) {
  const auto& sc = scene();
  const TaskKind kind = kTaskKinds[std::size_t(state.range(0))];
  TaskSpec t;
  switch (kind) {
    case TaskKind::volume: t = p_task(); break;
    case TaskKind::isosurface: t = TaskSpec::isosurface(0, 0.3f); break;
    case TaskKind::slice:
      t = TaskSpec::slice(0, 2, sc.grid.centre()[2], TransferFunction::preset("diverging"), ValueWindow::absolute(-1, 1));
      break;
    case TaskKind::mip: t = TaskSpec::mip(0, TransferFunction::preset("hot"), ValueWindow::absolute(0, 1)); break;
  }
  state.SetLabel(to_string(kind));
  const std::vector<TaskSpec> tasks{t};
  std::vector<PartialImage> out(1);
  RenderStats total;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) total = add(total, render_brick(kMain, sc.fields, tasks, out, RenderOptions{}));
  const double cpu = process_cpu_seconds() - cpu0;
  report(state, total, total.seconds, cpu);
  state.counters["cpu_s_frame"] = cpu / double(state.iterations());
}
BENCHMARK(BM_TaskKinds)->ArgName("kind")->DenseRange(0, int(kTaskKinds.size()) - 1)->Iterations(2)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PrepareFields(benchmark::State& state) {
  const auto& sc = scene();
  for (auto _ : state) {
    PreparedField a(FieldView::whole(sc.grid, sc.p.data())), b(FieldView::whole(sc.grid, sc.s.data()));
    benchmark::DoNotOptimize(a.cells.total() + b.cells.total());
  }
}
BENCHMARK(BM_PrepareFields)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
