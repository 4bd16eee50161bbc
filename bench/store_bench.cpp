// Store benchmarks: database open time (manifest only, no movie opened) for 10^2 .. 10^5 streams, and
// manifest size. Only manifests are written in the fixture: open() never touches a movie, which is
// exactly the claim measured here (open time independent of the number of streams).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <sys/resource.h>

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

// Issue 46, in situ: every stream gets one 40x32 frame per snapshot, then a checkpoint, through one
// DatabaseWriter (one rank). Args: layout (0 files, 1 packed), cameras, tasks. Counters: process CPU
// (getrusage: all threads) per stream per snapshot, heap in use (mallinfo2) per stream after the
// first snapshot beyond what create() left, and files in the database. The files layout keeps a
// muxer per stream (~1 MB), so it runs at 10^3 streams only.
double process_cpu_seconds() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void BM_InsituSnapshot(benchmark::State& state) {
  const bool packed = state.range(0) == 1;
  const int cameras = int(state.range(1)), tasks = int(state.range(2));
  testing::TempDir dir("bench-pack");
  Manifest m = testing::sample_manifest(cameras, tasks, 40, 32);
  m.video.gop = 1;
  WriterOptions o;
  o.layout = packed ? LayoutChoice::packed : LayoutChoice::files;
  const panoptes::Image frame = synthetic_frame(0, 0, 0, 40, 32);
  DatabaseWriter w = DatabaseWriter::create(dir.path / "db", m, o);
  w.append(0, 0, frame);  // one-time encoder set-up outside the measurement
  const double heap0 = double(mallinfo2().uordblks);
  double heap1 = 0, cpu = 0;
  int snapshot = 0;
  for (auto _ : state) {
    const double c0 = process_cpu_seconds();
    for (int c = 0; c < cameras; ++c)
      for (int t = (snapshot == 0 && c == 0) ? 1 : 0; t < tasks; ++t) w.append(c, t, frame);
    w.checkpoint();
    cpu += process_cpu_seconds() - c0;
    if (snapshot++ == 0) heap1 = double(mallinfo2().uordblks);
  }
  const double streams = double(cameras) * tasks;
  w.finalize();
  std::int64_t files = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path / "db")) files += e.is_regular_file();
  state.counters["streams"] = streams;
  state.counters["cpu_us_per_stream"] = 1e6 * cpu / double(state.iterations()) / streams;
  state.counters["heap_bytes_per_stream"] = (heap1 - heap0) / streams;
  state.counters["files"] = double(files);
}
BENCHMARK(BM_InsituSnapshot)
    ->ArgNames({"packed", "cameras", "tasks"})
    ->Args({0, 100, 10})    // files, 10^3 streams
    ->Args({1, 100, 10})    // packed, 10^3
    ->Args({1, 100, 100})   // packed, 10^4
    ->Args({1, 1000, 100})  // packed, 10^5
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
