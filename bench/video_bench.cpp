// Movie writer/reader figures at the paper's frame size (920 x 896): encode and decode speed, random-
// access latency per GOP, bytes per frame, memory per open writer, and a settings sweep (CRF, preset,
// GOP) used to choose the defaults in video_settings.hpp (see docs/formats.md).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "video/movie_reader.hpp"
#include "video/movie_test_util.hpp"
#include "video/movie_writer.hpp"

namespace {

using namespace panoptes;
using namespace panoptes::video;
namespace fs = std::filesystem;

constexpr int kWidth = 920, kHeight = 896;
constexpr int kFrames = 30;  // distinct source frames (the movies cycle through them)
constexpr double kRawFrameBytes = double(kWidth) * kHeight * 3;

const std::vector<Image>& source_frames() {
  static const std::vector<Image> frames = [] {
    std::vector<Image> v;
    for (int i = 0; i < kFrames; ++i) v.push_back(testing::make_test_frame(kWidth, kHeight, i));
    return v;
  }();
  return frames;
}

// A scratch directory for the movies, removed at exit.
struct ScratchDir {
  fs::path path = fs::temp_directory_path() / ("panoptes_video_bench_" + std::to_string(getpid()));
  ScratchDir() { fs::create_directories(path); }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};
const fs::path& bench_dir() {
  static const ScratchDir dir;
  return dir.path;
}

// Resident set size in bytes (from /proc/self/statm).
double rss_bytes() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return double(resident) * double(sysconf(_SC_PAGESIZE));
}

std::string write_movie(const std::string& name, const VideoSettings& s, int frames) {
  const std::string path = (bench_dir() / name).string();
  MovieWriter w(path, kWidth, kHeight, s);
  for (int i = 0; i < frames; ++i) w.append(source_frames()[i % kFrames]);
  w.close();
  return path;
}

double mean_psnr(const std::string& path, double* worst) {
  MovieReader r(path);
  double sum = 0;
  *worst = 1e9;
  for (int i = 0; i < r.frame_count(); ++i) {
    const double p = psnr(r.read_rgba(i), source_frames()[i % kFrames]);
    sum += p;
    *worst = std::min(*worst, p);
  }
  return sum / r.frame_count();
}

VideoSettings with_gop(int gop) {
  VideoSettings s;
  s.gop = gop;
  return s;
}

// Encode speed (default settings but the given GOP): one appended frame per iteration; items/s is
// frames per CPU-second of the encoding thread (x264 runs single-threaded in the calling thread).
void BM_Encode(benchmark::State& state) {
  const auto s = with_gop(int(state.range(0)));
  source_frames();
  const std::string path = (bench_dir() / "encode.mp4").string();
  auto writer = std::make_unique<MovieWriter>(path, kWidth, kHeight, s);
  std::int64_t n = 0;
  for (auto _ : state) writer->append(source_frames()[n++ % kFrames]);
  writer->close();
  state.SetItemsProcessed(n);
  const double bytes = double(fs::file_size(path)) / double(n);
  state.counters["bytes_per_frame"] = bytes;
  state.counters["ratio_to_raw_pct"] = 100.0 * bytes / kRawFrameBytes;
  double worst = 0;
  state.counters["psnr_db"] = mean_psnr(path, &worst);
  state.counters["psnr_min_db"] = worst;
}
BENCHMARK(BM_Encode)->Arg(1)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond)->MinTime(0.5);

// Sequential decode to YUV planes (the player's path): items/s is frames per CPU-second.
void BM_DecodeSequential(benchmark::State& state) {
  const int gop = int(state.range(0));
  const std::string path = write_movie("decode" + std::to_string(gop) + ".mp4", with_gop(gop), 60);
  MovieReader reader(path);
  YuvFrame yuv;
  int i = 0;
  for (auto _ : state) {
    reader.read(i, yuv);
    i = (i + 1) % reader.frame_count();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DecodeSequential)->Arg(1)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond)->MinTime(0.5);

// Random access: shuffled reads of every frame of a 60-frame movie; wall-clock latency per read.
void BM_RandomAccess(benchmark::State& state) {
  const int gop = int(state.range(0));
  const std::string path = write_movie("random" + std::to_string(gop) + ".mp4", with_gop(gop), 60);
  MovieReader reader(path);
  std::vector<int> order(reader.frame_count());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 rng(42);
  std::vector<double> ms;
  YuvFrame yuv;
  std::size_t k = 0;
  for (auto _ : state) {
    if (k % order.size() == 0) std::shuffle(order.begin(), order.end(), rng);
    const auto t0 = std::chrono::steady_clock::now();
    reader.read(order[k++ % order.size()], yuv);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.counters["max_ms"] = ms.back();
}
// 60 iterations = one shuffled pass over all frames, so median and max cover every frame position.
BENCHMARK(BM_RandomAccess)->Arg(1)->Arg(10)->Arg(30)->Iterations(60)->Unit(benchmark::kMillisecond);

// Opening a movie: the one-pass packet index of a 60-frame movie.
void BM_OpenReader(benchmark::State& state) {
  const std::string path = write_movie("open.mp4", with_gop(10), 60);
  for (auto _ : state) {
    MovieReader r(path);
    benchmark::DoNotOptimize(r.frame_count());
  }
}
BENCHMARK(BM_OpenReader)->Unit(benchmark::kMicrosecond);

// Resident memory per open writer: RSS growth while `writers` writers are open, each having written
// four frames. Measured in a fresh process (this program re-run with --writer-memory), since freed
// memory of earlier benchmarks would otherwise be reused and hide the growth.
double writer_memory_child(const VideoSettings& s, int writers) {
  std::vector<Image> frames = {testing::make_test_frame(kWidth, kHeight, 0), testing::make_test_frame(kWidth, kHeight, 1)};
  std::vector<std::unique_ptr<MovieWriter>> open;
  open.reserve(writers);
  const double before = rss_bytes();
  for (int i = 0; i < writers; ++i) {
    open.push_back(std::make_unique<MovieWriter>((bench_dir() / ("mem" + std::to_string(i) + ".mp4")).string(),
                                                 kWidth, kHeight, s));
    for (int k = 0; k < 4; ++k) open.back()->append(frames[k % 2]);  // past x264's start-up allocations
  }
  return (rss_bytes() - before) / writers;
}

// MB per writer from a child process; -1 if the child failed.
double writer_memory_mb(const VideoSettings& s, int writers) {
  const std::string cmd = "/proc/" + std::to_string(getpid()) + "/exe --writer-memory " + s.preset + " " +
                          std::to_string(s.crf) + " " + std::to_string(s.gop) + " " + std::to_string(writers);
  FILE* p = popen(cmd.c_str(), "r");
  double bytes = -1;
  if (!p || std::fscanf(p, "%lf", &bytes) != 1) bytes = -1;
  if (p) pclose(p);
  return bytes < 0 ? -1 : bytes / 1e6;
}

// Resident growth per open reader that has decoded one frame (the player keeps many open), measured
// like the writers in a fresh process (--reader-memory).
double reader_memory_child(int gop, int readers) {
  const std::string path = write_movie("readers.mp4", with_gop(gop), 10);
  std::vector<std::unique_ptr<MovieReader>> open;
  std::vector<YuvFrame> frames(readers);
  open.reserve(readers);
  const double before = rss_bytes();
  for (int i = 0; i < readers; ++i) {
    open.push_back(std::make_unique<MovieReader>(path));
    open.back()->read(5, frames[i]);
  }
  return (rss_bytes() - before) / readers;
}

void BM_ReaderMemory(benchmark::State& state) {
  for (auto _ : state) {
    const std::string cmd = "/proc/" + std::to_string(getpid()) + "/exe --reader-memory " +
                            std::to_string(state.range(0)) + " 20";
    FILE* p = popen(cmd.c_str(), "r");
    double bytes = -1;
    if (!p || std::fscanf(p, "%lf", &bytes) != 1) bytes = -1;
    if (p) pclose(p);
    if (bytes < 0) state.SkipWithError("the --reader-memory child failed");
    state.counters["MB_per_reader"] = bytes / 1e6;  // includes the reader's decoded YUV frame (1.24 MB)
  }
}
BENCHMARK(BM_ReaderMemory)->Arg(1)->Arg(10)->Iterations(1)->Unit(benchmark::kMillisecond);

void measure_writer_memory(benchmark::State& state, const VideoSettings& s, int writers) {
  for (auto _ : state) {
    const double mb = writer_memory_mb(s, writers);
    if (mb < 0) state.SkipWithError("the --writer-memory child failed");
    state.counters["MB_per_writer"] = mb;
  }
}
void BM_WriterMemory(benchmark::State& state) {
  const int gop = int(state.range(0));
  measure_writer_memory(state, with_gop(gop), gop == 1 ? 20 : 10);
}
BENCHMARK(BM_WriterMemory)->Arg(1)->Arg(10)->Arg(30)->Iterations(1)->Unit(benchmark::kMillisecond);

// Settings sweep: 30 frames per configuration. Reports encode frames per CPU-second, bytes per frame,
// mean/min PSNR and random-access median/max; args are (crf, preset index, gop).
const char* kPresets[] = {"ultrafast", "superfast", "veryfast", "faster", "fast", "medium"};
void BM_Settings(benchmark::State& state) {
  VideoSettings s;
  s.crf = int(state.range(0));
  s.preset = kPresets[state.range(1)];
  s.gop = int(state.range(2));
  state.SetLabel(s.preset);
  source_frames();
  const std::string path = (bench_dir() / "sweep.mp4").string();
  std::int64_t frames = 0;
  for (auto _ : state) {
    MovieWriter w(path, kWidth, kHeight, s);
    for (int i = 0; i < kFrames; ++i) w.append(source_frames()[i]);
    w.close();
    frames += kFrames;
  }
  state.SetItemsProcessed(frames);
  const double bytes = double(fs::file_size(path)) / kFrames;
  state.counters["bytes_per_frame"] = bytes;
  state.counters["ratio_to_raw_pct"] = 100.0 * bytes / kRawFrameBytes;
  double worst = 0;
  state.counters["psnr_db"] = mean_psnr(path, &worst);
  state.counters["psnr_min_db"] = worst;
  MovieReader r(path);
  std::vector<double> ms;
  YuvFrame yuv;
  std::vector<int> order(kFrames);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  for (int i : order) {
    const auto t0 = std::chrono::steady_clock::now();
    r.read(i, yuv);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  state.counters["ra_median_ms"] = ms[ms.size() / 2];
  state.counters["ra_max_ms"] = ms.back();
  state.counters["MB_per_writer"] = writer_memory_mb(s, 5);
}
void sweep_args(benchmark::internal::Benchmark* b) {
  for (int preset : {0, 1, 2, 3, 5}) b->Args({20, preset, 1});  // presets, intra-only
  for (int crf : {16, 18, 22, 24}) b->Args({crf, 2, 1});         // quality, intra-only
  for (int gop : {10, 30}) b->Args({20, 2, gop});                // with P-frames
  b->Args({20, 0, 10});
}
BENCHMARK(BM_Settings)->Apply(sweep_args)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  if (argc == 6 && std::string(argv[1]) == "--writer-memory") {
    VideoSettings s;
    s.preset = argv[2];
    s.crf = std::atoi(argv[3]);
    s.gop = std::atoi(argv[4]);
    std::printf("%.0f\n", writer_memory_child(s, std::atoi(argv[5])));
    return 0;
  }
  if (argc == 4 && std::string(argv[1]) == "--reader-memory") {
    std::printf("%.0f\n", reader_memory_child(std::atoi(argv[2]), std::atoi(argv[3])));
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
