// Player figures (issue 6): database open time and resident memory versus the number of streams
// (manifest-only databases), switch latency at 920x896 while playing at 30 fps with prefetch on and
// off, and the sustained decode rate of one 920x896 stream on one core.
#include <benchmark/benchmark.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "player/engine.hpp"
#include "player/test_db.hpp"
#include "store/manifest.hpp"

namespace {

using namespace panoptes;
using namespace panoptes::player;
namespace fs = std::filesystem;

constexpr int kWidth = 920, kHeight = 896;
constexpr int kCameras = 4, kFrames = 45;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double rss_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return double(resident) * double(::sysconf(_SC_PAGE_SIZE)) / (1024.0 * 1024.0);
}

testing::TempDir& scratch() {
  static testing::TempDir dir("player-bench");
  return dir;
}

// A manifest-only database of cameras x tasks streams (open must not touch the movies).
fs::path manifest_only_db(int cameras, int tasks) {
  const fs::path dir = scratch().path / ("manifest_" + std::to_string(cameras) + "x" + std::to_string(tasks));
  if (!fs::exists(dir / store::kManifestFileName)) {
    fs::create_directories(dir);
    store::Manifest m = testing::ring_manifest(cameras, tasks);
    m.status = store::Status::complete;
    m.frames_written = 60;
    store::write_manifest_atomic(dir / store::kManifestFileName, m);
  }
  return dir;
}

// A small real database at the paper's frame size: kCameras on a ring, one task, kFrames frames,
// written with the video module's default settings.
const fs::path& real_db() {
  static const fs::path dir = [] {
    const fs::path d = scratch().path / "real";
    testing::write_stamped(d, testing::ring_manifest(kCameras, 1, kWidth, kHeight), kFrames);
    return d;
  }();
  return dir;
}

// Opens `dir` with player::Engine in THIS process and prints "open_ms rss_MiB hwm_MiB" (resident memory
// after the open and its peak). Run in a fresh child process (see BM_Open) so that the memory the
// benchmark itself used to write the database does not count.
int open_child(const char* dir) {
  const double t0 = now_s();
  Engine engine{fs::path(dir)};
  const double ms = (now_s() - t0) * 1e3;
  benchmark::DoNotOptimize(engine.frame_count());
  std::ifstream status("/proc/self/status");
  double hwm_kib = 0;
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) hwm_kib = std::stod(line.substr(6));
  std::printf("%.3f %.2f %.2f\n", ms, rss_mib(), hwm_kib / 1024.0);
  return 0;
}

// Runs this program as `--open-child DIR` and parses its line.
bool open_in_child(const fs::path& dir, double& ms, double& rss, double& hwm) {
  int fds[2];
  if (::pipe(fds) != 0) return false;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  const std::string self = fs::read_symlink("/proc/self/exe").string(), dir_s = dir.string();
  char* argv[] = {const_cast<char*>(self.c_str()), const_cast<char*>("--open-child"), const_cast<char*>(dir_s.c_str()),
                  nullptr};
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, self.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  std::string out;
  char buf[256];
  for (ssize_t n; rc == 0 && (n = ::read(fds[0], buf, sizeof buf)) > 0;) out.append(buf, std::size_t(n));
  ::close(fds[0]);
  int status = 0;
  if (rc != 0 || ::waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return false;
  std::istringstream in(out);
  return bool(in >> ms >> rss >> hwm);
}

// Open time and resident memory of a fresh process that opens a C x T database with player::Engine
// (what `panoptes play` does before showing the first frame; no movie is opened).
void BM_Open(benchmark::State& state) {
  const int cameras = int(state.range(0)), tasks = int(state.range(1));
  const fs::path dir = manifest_only_db(cameras, tasks);
  double worst_ms = 0, rss = 0, hwm = 0;
  for (auto _ : state) {
    double ms = 0, r = 0, h = 0;
    if (!open_in_child(dir, ms, r, h)) {
      state.SkipWithError("the --open-child process failed");
      return;
    }
    worst_ms = std::max(worst_ms, ms);
    rss = std::max(rss, r);
    hwm = std::max(hwm, h);
    state.SetIterationTime(ms / 1e3);
  }
  std::uintmax_t bytes = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) bytes += e.file_size();
  state.counters["streams"] = double(cameras) * tasks;
  state.counters["open_ms_max"] = worst_ms;
  state.counters["rss_MiB"] = rss;
  state.counters["peak_rss_MiB"] = hwm;
  state.counters["db_MB"] = double(bytes) / 1e6;
}
// 10^2, 10^4, 10^5 streams as cameras x tasks; then the largest camera tables: 10^5 and 10^6 cameras.
BENCHMARK(BM_Open)->Args({10, 10})->Args({100, 100})->Args({1000, 100})->Args({100000, 1})->Args({1000000, 1})
    ->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

// Plays for `seconds` of wall time at 30 fps (sleeping to each display deadline, like vsync), switching
// camera every 5th frame (6 switches per second), and reports the engine's switch latencies.
void BM_SwitchLatency(benchmark::State& state) {
  const bool prefetch = state.range(0) != 0;
  const int nice = int(state.range(1));
  const fs::path& db = real_db();
  constexpr int kTicks = 150;  // 5 s
  std::vector<double> latencies, frame_ms;
  std::int64_t hits = 0, switches = 0;
  for (auto _ : state) {
    EngineOptions o;
    o.prefetch = prefetch;
    o.prefetch_threads = 2;
    o.prefetch_nice = nice;
    Engine engine(db, o);
    engine.current_frame();
    const double start = now_s();
    for (int k = 0; k < kTicks; ++k) {
      const double deadline = start + k / 30.0;
      const double wait = deadline - now_s();
      if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
      engine.tick();
      if (k % 5 == 2) engine.apply((k / 5) % 3 == 2 ? Action::camera_left : Action::camera_right);
      const double t0 = now_s();
      benchmark::DoNotOptimize(engine.current_frame());
      frame_ms.push_back((now_s() - t0) * 1e3);
    }
    const Statistics st = engine.statistics();
    for (const auto& s : st.switches) {
      latencies.push_back(s.latency_ms);
      hits += s.cache_hit;
      ++switches;
    }
  }
  const Summary s = summarize(latencies), f = summarize(frame_ms);
  state.counters["switches"] = double(switches);
  state.counters["switch_hit_pct"] = switches ? 100.0 * double(hits) / double(switches) : 0;
  state.counters["switch_p50_ms"] = s.p50;
  state.counters["switch_p99_ms"] = s.p99;
  state.counters["switch_max_ms"] = s.max;
  state.counters["frame_p99_ms"] = f.p99;
}
// prefetch:1/nice:5 is the earlier default (prefetch threads at nice +5), kept for comparison.
BENCHMARK(BM_SwitchLatency)->Args({1, 0})->Args({1, 5})->Args({0, 0})->ArgNames({"prefetch", "nice"})
    ->Iterations(1)->Unit(benchmark::kSecond);

// Sequential decode of one 920x896 stream on the calling thread (the decoder is single-threaded).
void BM_DecodeRate(benchmark::State& state) {
  const auto database = store::Database::open(real_db());
  auto reader = database.stream(0, 0);
  video::YuvFrame frame;
  std::int64_t frames = 0;
  double seconds = 0;
  for (auto _ : state) {
    const double t0 = now_s();
    for (int i = 0; i < reader->frame_count(); ++i) reader->read(i, frame);
    seconds += now_s() - t0;
    frames += reader->frame_count();
  }
  state.counters["decode_fps"] = double(frames) / seconds;
  state.counters["ms_per_frame"] = 1e3 * seconds / double(frames);
}
BENCHMARK(BM_DecodeRate)->Iterations(4)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--open-child") return open_child(argv[2]);
  // For profiling the open by hand: `player_bench --make-db DIR C T`, then `player_bench --open-child DIR`.
  if (argc == 5 && std::string(argv[1]) == "--make-db") {
    store::Manifest m = testing::ring_manifest(std::stoi(argv[3]), std::stoi(argv[4]));
    m.status = store::Status::complete;
    m.frames_written = 60;
    fs::create_directories(argv[2]);
    store::write_manifest_atomic(fs::path(argv[2]) / store::kManifestFileName, m);
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
