// Store benchmarks: database open time (manifest only, no movie opened) for 10^2 .. 10^5 streams, and
// manifest size. Only manifests are written in the fixture: open() never touches a movie, which is
// exactly the claim measured here (open time independent of the number of streams).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>

#include "store/camera_table.hpp"
#include "store/database.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"

namespace {

using namespace panoptes::store;

// One database directory per (cameras, tasks), created on first use and kept for the whole run.
const std::filesystem::path& database_dir(int cameras, int tasks) {
  static std::map<std::pair<int, int>, std::unique_ptr<testing::TempDir>> dirs;
  auto& d = dirs[{cameras, tasks}];
  if (!d) {
    d = std::make_unique<testing::TempDir>("bench");
    Manifest m = testing::sample_manifest(cameras, tasks, 920, 896);
    m.frames_written = 60;
    m.status = Status::complete;
    for (int i = 0; i < 60; ++i) m.times.push_back(0.1 * i);
    write_manifest_atomic(d->path / kManifestFileName, m);
  }
  return d->path;
}

// Args: cameras, tasks. Streams = cameras × tasks.
void BM_DatabaseOpen(benchmark::State& state) {
  const int cameras = int(state.range(0)), tasks = int(state.range(1));
  const auto& dir = database_dir(cameras, tasks);
  std::int64_t streams = 0;
  for (auto _ : state) {
    Database db = Database::open(dir);
    streams = db.stream_count();
    benchmark::DoNotOptimize(db);
  }
  const double json_bytes = double(std::filesystem::file_size(dir / kManifestFileName));
  const double table_bytes = double(std::filesystem::file_size(dir / referenced_camera_table(dir / kManifestFileName)));
  state.counters["streams"] = double(streams);
  state.counters["manifest_bytes"] = json_bytes;
  state.counters["table_bytes"] = table_bytes;
  state.counters["bytes_per_stream"] = (json_bytes + table_bytes) / double(streams);
}
BENCHMARK(BM_DatabaseOpen)
    ->ArgNames({"cameras", "tasks"})
    ->Args({10, 10})        // 10^2 streams
    ->Args({130, 3})        // the paper's 390 movies
    ->Args({100, 100})      // 10^4
    ->Args({1000, 100})     // 10^5, many cameras and parameters
    ->Args({100, 1000})     // 10^5, thousands of parameters per camera
    ->Args({10000, 10})     // 10^5, very many cameras
    ->Args({100000, 1})     // 10^5 cameras (worst case: size ∝ cameras)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Writing a whole manifest: camera table + panoptes.json, each temp + fsync + rename (DatabaseWriter::create).
void BM_ManifestAtomicWrite(benchmark::State& state) {
  const int cameras = int(state.range(0)), tasks = int(state.range(1));
  testing::TempDir dir("bench-write");
  const Manifest m = testing::sample_manifest(cameras, tasks, 920, 896);
  for (auto _ : state) write_manifest_atomic(dir.path / kManifestFileName, m);
  state.counters["manifest_bytes"] = double(std::filesystem::file_size(dir.path / kManifestFileName));
}
BENCHMARK(BM_ManifestAtomicWrite)->ArgNames({"cameras", "tasks"})->Args({1000, 100})->Args({10000, 10})
    ->Args({100000, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

// A checkpoint's write: panoptes.json only (temp + fsync + rename), referring to the camera table written
// once at create — what DatabaseWriter::checkpoint() does after every snapshot.
void BM_CheckpointWrite(benchmark::State& state) {
  const int cameras = int(state.range(0)), tasks = int(state.range(1));
  testing::TempDir dir("bench-checkpoint");
  Manifest m = testing::sample_manifest(cameras, tasks, 920, 896);
  const CameraTableRef table = write_camera_table(dir.path, m);
  for (auto _ : state) {
    ++m.frames_written;
    write_manifest_atomic(dir.path / kManifestFileName, m, table);
  }
  state.counters["manifest_bytes"] = double(std::filesystem::file_size(dir.path / kManifestFileName));
}
BENCHMARK(BM_CheckpointWrite)->ArgNames({"cameras", "tasks"})->Args({1000, 100})->Args({100000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// `panoptes synth-db` workload: 10,000 tiny streams (64x64, 10 frames), every stream encoded and
// closed in turn on all cores. Real time is the figure that matters (target: well under a minute).
void BM_SyntheticDatabase(benchmark::State& state) {
  SyntheticOptions o;
  o.cameras = int(state.range(0));
  o.tasks = int(state.range(1));
  o.frames = 10;
  o.width = o.height = 64;
  o.video.gop = 10;  // as `panoptes synth-db` (one encoder per movie; GOP 1 opens one per frame)
  for (auto _ : state) {
    testing::TempDir dir("bench-synth");
    write_synthetic_database(dir.path / "db", o);
  }
  state.counters["streams_per_s"] =
      benchmark::Counter(double(o.cameras) * o.tasks * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SyntheticDatabase)->ArgNames({"cameras", "tasks"})->Args({1000, 10})->Iterations(1)
    ->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
