// The in-situ grid stage's cost (issue 33): insitu::GridAdapter resampling a Yin-Yang shell (both
// patches in one process, the analytic grid::ShellField) onto the uniform grid the session renders.
//   BM_Adapt/NR         adapt() alone, Yin-Yang NR x 2NR x 6NR per patch onto a 4NR-point cover:
//                       ms_per_Mpoint = milliseconds per million SOURCE points (both patches).
//   BM_ShellSnapshot/W  one snapshot as a simulation pays it: adapt() + Session::snapshot(), 3 tasks
//                       (volume, isosurface, slice), NR = 48 (2.65 M source points, a 192^3 cover).
//                       adapt_pct = adapt / (adapt + snapshot): target <= 10 %.
//                       /256: the paper's 130 Yin-Yang cameras at 256x256 (13x fewer pixels than the
//                       paper's: the adapter's hardest share).
//                       /920: the paper's 920x896 images from 8 of the Yin-Yang cameras (yinyang:2x2; all
//                       130 would take minutes a snapshot); adapt_pct_130 projects the share for all 130
//                       cameras (render time x 130/8: every camera renders the same cover).
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <numbers>

#include "grid/grid_description.hpp"
#include "grid/sample.hpp"
#include "insitu/config.hpp"
#include "insitu/grid_adapter.hpp"
#include "insitu/session.hpp"

using namespace panoptes;

namespace {

grid::GridDescription shell_grid(int nr) {
  std::vector<double> r(static_cast<std::size_t>(nr));
  for (int i = 0; i < nr; ++i) r[std::size_t(i)] = 0.35 + 0.65 * i / (nr - 1);
  return grid::GridDescription::yinyang_standard(r, 2 * nr, 6 * nr);
}

struct Source {
  grid::GridDescription grid;
  std::vector<std::vector<float>> values;  // per patch
  std::vector<insitu::GridBlock> blocks;
  std::vector<insitu::FieldInput> inputs() const {
    std::vector<insitu::FieldInput> v;
    for (std::size_t p = 0; p < values.size(); ++p) v.push_back({"T", values[p].data(), insitu::ScalarType::f32, {0, 0, 0}});
    return v;
  }
};

Source make_source(int nr) {
  Source s{shell_grid(nr), {}, {}};
  const grid::ShellField f{0.35, 1.0, 0.3};
  for (int p = 0; p < 2; ++p) {
    s.values.push_back(grid::sample(s.grid, p, [&](const Vec3& x) { return f(x); }));
    s.blocks.push_back(insitu::GridBlock::whole(s.grid, p));
  }
  return s;
}

double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void BM_Adapt(benchmark::State& state) {
  const int nr = int(state.range(0));
  const Source s = make_source(nr);
  insitu::GridAdapter adapter(s.grid, s.blocks, {4 * nr, 0.0f});
  const auto in = s.inputs();
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) benchmark::DoNotOptimize(adapter.adapt(in));
  const double wall = seconds_since(t0), cpu = process_cpu_seconds() - cpu0;
  const double points = 2.0 * double(s.grid.points_per_patch()), n = double(state.iterations());
  const auto& g = adapter.render_grid();
  state.counters["source_Mpoints"] = points / 1e6;
  state.counters["cover_Mpoints"] = double(g.dims[0]) * g.dims[1] * g.dims[2] / 1e6;
  state.counters["ms_per_Mpoint"] = 1e3 * wall / n / (points / 1e6);
  // Every thread's CPU time (OpenMP included): the figure a loaded, shared machine distorts least.
  state.counters["cpu_ms_per_Mpoint"] = 1e3 * cpu / n / (points / 1e6);
}
BENCHMARK(BM_Adapt)->Arg(24)->Arg(48)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ShellSnapshot(benchmark::State& state) {
  const int nr = 48;
  const bool paper_pixels = state.range(0) == 920;
  const std::string size = paper_pixels ? "width = 920\nheight = 896\n" : "width = 256\nheight = 256\n";
  const std::string rig = paper_pixels ? "yinyang:2x2" : "yinyang";
  const Source s = make_source(nr);
  insitu::GridAdapter adapter(s.grid, s.blocks, {4 * nr, 0.0f});
  const std::string out = (std::filesystem::temp_directory_path() / ("grid_adapter_bench_" + std::to_string(::getpid()))).string();
  insitu::SessionConfig cfg = insitu::parse_session_config_text(
      "[output]\ndir = \"" + out + "\"\noverwrite = true\n[image]\n" + size + "[rig]\nspec = \"" + rig + "\"\n"
      "[schedule]\nevery_steps = 1\n"
      "[[task]]\nname = \"T\"\ntype = \"volume\"\nfield = \"T\"\npreset = \"diverging\"\nrelative = false\nwindow = [-1.0, 1.0]\n"
      "[[task]]\nname = \"iso\"\ntype = \"isosurface\"\nfield = \"T\"\nisovalues = [0.5]\n"
      "[[task]]\nname = \"slice\"\ntype = \"slice\"\nfield = \"T\"\naxis = \"z\"\npositions = [0.5]\npreset = \"diverging\"\n"
      "relative = false\nwindow = [-1.0, 1.0]\n",
      "grid_adapter_bench");
  cfg.source_grid = s.grid.summary();
  insitu::Session session(cfg, adapter.render_grid(), adapter.render_block());
  const auto in = s.inputs();
  double adapt_s = 0, snapshot_s = 0, adapt_cpu = 0, snapshot_cpu = 0;
  int n = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    double c0 = process_cpu_seconds();
    const auto adapted = adapter.adapt(in);
    adapt_s += seconds_since(t0);
    adapt_cpu += process_cpu_seconds() - c0;
    t0 = std::chrono::steady_clock::now();
    c0 = process_cpu_seconds();
    session.snapshot(double(n), adapted);
    snapshot_s += seconds_since(t0);
    snapshot_cpu += process_cpu_seconds() - c0;
    ++n;
  }
  session.finalize();
  std::filesystem::remove_all(out);
  state.counters["images"] = double(session.camera_count()) * session.task_count();
  state.counters["adapt_s"] = adapt_s / n;
  state.counters["render_s"] = snapshot_s / n;
  state.counters["adapt_pct"] = 100 * adapt_s / (adapt_s + snapshot_s);
  state.counters["adapt_cpu_pct"] = 100 * adapt_cpu / (adapt_cpu + snapshot_cpu);
  state.counters["cameras"] = double(session.camera_count());
  state.counters["adapt_pct_130"] = 100 * adapt_s / (adapt_s + snapshot_s * 130.0 / double(session.camera_count()));
  state.counters["adapt_ms_per_Mpoint"] = 1e3 * adapt_s / n / (2.0 * double(s.grid.points_per_patch()) / 1e6);
}
BENCHMARK(BM_ShellSnapshot)->Arg(256)->Arg(920)->Unit(benchmark::kSecond)->Iterations(2)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
