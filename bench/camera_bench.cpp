// Camera module benchmarks: rig generation, navigation-graph construction and nearest-camera queries
// for rigs of 130 to 10^6 cameras (the graph is built once per database; nearest() runs on every
// mouse-drag event in the player).
#include <benchmark/benchmark.h>

#include <random>
#include <string>

#include "camera/navigation.hpp"
#include "camera/rig_spec.hpp"

using namespace panoptes;
using namespace panoptes::camera;

namespace {
const Domain kDomain{{0, 0, 0}, {256, 512, 160}};

std::string spec_for(int kind, int n) {
  switch (kind) {
    case 0: {  // Yin-Yang with square cells: 2 · t · 3t cameras
      int t = 1;
      while (2 * (t + 1) * 3 * (t + 1) <= n) ++t;
      return n == 130 ? "yinyang" : "yinyang:" + std::to_string(t) + "x" + std::to_string(3 * t);
    }
    case 1: return "fibonacci:" + std::to_string(n);
    default: return "latlon";
  }
}

void BM_MakeRig(benchmark::State& state) {
  const std::string spec = spec_for(int(state.range(0)), int(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(make_rig(spec, kDomain));
  state.SetLabel(spec);
}

void BM_NavigationGraph(benchmark::State& state) {
  const Rig rig = make_rig(spec_for(int(state.range(0)), int(state.range(1))), kDomain);
  for (auto _ : state) benchmark::DoNotOptimize(build_navigation_graph(rig));
  state.SetLabel(rig.spec + " (" + std::to_string(rig.size()) + " cameras)");
  state.counters["cameras/s"] = benchmark::Counter(double(rig.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Nearest(benchmark::State& state) {
  const Rig rig = make_rig(spec_for(1, int(state.range(0))), kDomain);
  const CameraLocator locator(rig);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  std::vector<Vec3> queries(4096);
  for (Vec3& q : queries) q = {g(rng), g(rng), g(rng)};
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(locator.nearest(queries[k]));
    k = (k + 1) & 4095;
  }
  state.SetLabel(rig.spec);
}

// Brute force for comparison: what nearest() would cost as a scan over every camera.
void BM_NearestBruteForce(benchmark::State& state) {
  const Rig rig = make_rig(spec_for(1, int(state.range(0))), kDomain);
  std::vector<Vec3> dirs;
  for (int c = 0; c < rig.size(); ++c) dirs.push_back(rig.direction(c));
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  std::vector<Vec3> queries(4096);
  for (Vec3& q : queries) q = normalize(Vec3{g(rng), g(rng), g(rng)});
  std::size_t k = 0;
  for (auto _ : state) {
    const Vec3& u = queries[k];
    int best = -1;
    double best_c = -2;
    for (int c = 0; c < int(dirs.size()); ++c) {
      const double d = dot(dirs[c], u);
      if (d > best_c) {
        best_c = d;
        best = c;
      }
    }
    benchmark::DoNotOptimize(best);
    k = (k + 1) & 4095;
  }
  state.SetLabel(rig.spec);
}
}  // namespace

// 10^6 cameras (issue 15: rigs of 10^6+ cameras must build in bounded time, with progress).
BENCHMARK(BM_MakeRig)
    ->Args({0, 130})
    ->Args({0, 10000})
    ->Args({0, 100000})
    ->Args({0, 1000000})
    ->Args({1, 1000000})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NavigationGraph)
    ->Args({0, 130})
    ->Args({1, 130})
    ->Args({2, 130})
    ->Args({0, 10000})
    ->Args({1, 10000})
    ->Args({0, 100000})
    ->Args({1, 100000})
    ->Args({1, 1000000})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Nearest)->Arg(130)->Arg(10000)->Arg(100000)->Arg(1000000);
BENCHMARK(BM_NearestBruteForce)->Arg(130)->Arg(10000)->Arg(100000);
BENCHMARK_MAIN();
