// In-situ engine benchmark: one snapshot of a synthetic two-field wave scene rendered from a rig for
// the paper's three tasks (p-wave, s-wave, both), composited and encoded into a database; a reduced
// paper setting (the 256x512x160 grid at 1/4 per axis, 1/2 the image size) and the demo's image size.
// Counters: seconds per snapshot split into copy / render / composite / encode / checkpoint,
// camera-frames per core-second, database bytes vs raw-field bytes, memory per open stream.
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <thread>

#include "insitu/session.hpp"
#include "render/synthetic_fields.hpp"

using namespace panoptes;

namespace {

std::int64_t rss_bytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return std::int64_t(resident) * ::sysconf(_SC_PAGESIZE);
}

std::int64_t dir_bytes(const std::filesystem::path& d) {
  std::int64_t n = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(d))
    if (e.is_regular_file()) n += std::int64_t(e.file_size());
  return n;
}

void BM_Snapshot(benchmark::State& state, const char* rig, int width, int height, render::Index3 dims) {
  const render::GridGeometry grid{dims, {0, 0, 0}, {1, 1, 1}};
  insitu::SessionConfig cfg = insitu::parse_session_config_text(R"(
[schedule]
every_steps = 1
[render]
sample_distance = 1.0
[[task]]
name = "p-wave"
field = "phi_p"
preset = "p-wave"
[[task]]
name = "s-wave"
field = "phi_s"
preset = "s-wave"
[[task]]
name = "p+s"
type = "volume2"
fields = ["phi_p", "phi_s"]
)",
                                                                "bench");
  cfg.rig = rig;
  cfg.width = width;
  cfg.height = height;
  cfg.overwrite = true;
  cfg.output_dir = (std::filesystem::temp_directory_path() / ("insitu_bench_" + std::to_string(::getpid()))).string();
  const Vec3 c = grid.centre();
  std::vector<render::WaveFront> p{{c, 0.3 * dims[0], 2.0, 1.0}}, s{{c + Vec3{0, 0, 3}, 0.2 * dims[0], 2.5, 1.0}};
  const std::vector<float> fp = render::wave_field(grid, p), fs = render::wave_field(grid, s);
  std::vector<float> fs_abs(fs);
  for (float& v : fs_abs) v = std::fabs(v);
  const std::int64_t rss0 = rss_bytes();
  insitu::Session session(cfg, grid, insitu::LocalBlock::whole(grid));
  const std::vector<insitu::FieldInput> in{{"phi_p", fp.data(), insitu::ScalarType::f32, {0, 0, 0}},
                                           {"phi_s", fs_abs.data(), insitu::ScalarType::f32, {0, 0, 0}}};
  double t = 0;
  for (auto _ : state) session.snapshot(t += 1, in);
  const std::int64_t rss1 = rss_bytes();
  const insitu::SessionStats st = session.stats();
  session.finalize();
  const double n = double(st.snapshots);
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  state.counters["copy_s"] = st.time.copy / n;
  state.counters["render_s"] = st.time.render / n;
  state.counters["composite_s"] = st.time.composite / n;
  state.counters["encode_s"] = st.time.encode / n;
  state.counters["checkpoint_s"] = st.time.checkpoint / n;
  state.counters["cam_frames_per_core_s"] = double(st.frames_encoded) / (st.time.total() * cores);
  const double raw = n * 2 * double(grid.dims[0]) * grid.dims[1] * grid.dims[2] * 4;
  const double db = double(dir_bytes(cfg.output_dir));
  state.counters["db_MB"] = db / 1e6;
  state.counters["raw_MB"] = raw / 1e6;
  state.counters["db_over_raw_pct"] = 100 * db / raw;
  const int streams = session.camera_count() * session.task_count();
  state.counters["streams"] = streams;
  state.counters["MB_per_open_stream"] = double(rss1 - rss0 - st.field_buffer_bytes - st.partial_buffer_bytes) / streams / 1e6;
  std::filesystem::remove_all(cfg.output_dir);
}

// Reduced paper setting: 64x128x40 grid (1/4 per axis), 26 of the 130 cameras, 460x448 images.
BENCHMARK_CAPTURE(BM_Snapshot, reduced_paper, "fibonacci:26", 460, 448, render::Index3{64, 128, 40})
    ->Unit(benchmark::kSecond)->Iterations(3)->UseRealTime();
// The demo's setting: 48x96x32 grid, 130 Yin-Yang cameras, 256x224 images.
BENCHMARK_CAPTURE(BM_Snapshot, demo, "yinyang", 256, 224, render::Index3{48, 96, 32})
    ->Unit(benchmark::kSecond)->Iterations(2)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
