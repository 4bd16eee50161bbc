// In-situ benchmark with the simulation phase (issue 5): the seismic solver and the in-situ pipeline
// as `panoptes run` drives them (bench/insitu_bench.hpp), one process, for
//   demo          examples/demo.toml: 48x96x32 grid, 130 Yin-Yang cameras x 3 tasks at 256x224;
//   paper_quarter examples/paper_quarter.toml: the paper's setting at 1/4 grid resolution per axis
//                 (64x128x40) and the paper's 920x896 images, 8 of its Yin-Yang cameras (yinyang:2x2)
//                 x 3 tasks, so that per-camera-frame costs at the paper's image size are measured.
// Counters (per snapshot, seconds): simulation / copy / render / composite / encode / checkpoint,
// camera-frames per core-second, database bytes vs raw-field bytes (phi_p, phi_s as float32), the
// process's resident memory with everything open, and memory per open stream.
//
// `insitu_bench --video-study [demo|paper]` (not run by scripts/bench; minutes) measures what the video settings
// give on the real frames of a setting: it runs the demo (every snapshot) and a stretch of
// paper_quarter, keeps the finished frames of a sample of streams, and encodes them with several
// GOP / quality / preset choices: bytes per frame, encode CPU time, PSNR, memory per open writer.
// docs/insitu.md reports the result and the demo's choice.
#include <benchmark/benchmark.h>
#include <time.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <map>

#include "bench/insitu_bench.hpp"
#include "video/movie_reader.hpp"
#include "video/movie_writer.hpp"

using namespace panoptes;

namespace {

void BM_Run(benchmark::State& state, bench::InsituSetting setting) {
  setting.config = std::string(PANOPTES_SOURCE_DIR) + "/" + setting.config;
  const std::string out =
      (std::filesystem::temp_directory_path() / ("insitu_bench_" + std::to_string(::getpid()))).string();
  bench::InsituResult r;
  for (auto _ : state) r = bench::run_insitu_setting(setting, out);
  std::filesystem::remove_all(out);
  auto& c = state.counters;
  c["simulation_s"] = r.simulation_s;
  c["copy_s"] = r.copy_s;
  c["render_s"] = r.render_s;
  c["composite_s"] = r.composite_s;
  c["encode_s"] = r.encode_s;
  c["checkpoint_s"] = r.checkpoint_s;
  c["snapshot_s"] = r.wall_s;
  // The in-situ overhead in wall time: visualization time / simulation time (the line `panoptes run`
  // prints counts CPU time of all threads instead, insitu/overhead.hpp; this stays comparable with the
  // figures recorded before).
  c["vis_over_sim"] = r.simulation_s > 0 ? (r.wall_s - r.simulation_s) / r.simulation_s : 0;
  c["streams"] = r.streams;
  c["cam_frames_per_core_s"] = r.frames_per_core_s();
  c["db_kB_per_snap"] = r.db_bytes / r.snapshots / 1e3;
  c["raw_kB_per_snap"] = r.raw_bytes / r.snapshots / 1e3;
  c["db_over_raw_pct"] = 100 * r.db_bytes / r.raw_bytes;
  c["rss_MB"] = r.rss_bytes_max / 1e6;
  c["MB_per_open_stream"] = r.stream_bytes_max / 1e6;
}

// Waves fill the domain after ~150 of the demo's 360 steps (and ~200 of paper_quarter's 480).
BENCHMARK_CAPTURE(BM_Run, demo, bench::InsituSetting{"examples/demo.toml", "", 150, 4})
    ->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_Run, paper_quarter, bench::InsituSetting{"examples/paper_quarter.toml", "yinyang:2x2", 200, 3})
    ->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

double cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Runs a setting like panoptes run and keeps the finished frames of the streams (camera, task) with
// camera % camera_step == 0: frames[stream][snapshot]. `raw_bytes` = phi_p + phi_s of one snapshot.
std::vector<std::vector<Image>> capture_frames(const bench::InsituSetting& s, int camera_step, double& raw_bytes) {
  std::ifstream in(s.config);
  if (!in) throw FileError(s.config, "cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string seis_text;
  insitu::SessionConfig cfg = insitu::parse_combined_config(
      ss.str(), s.config, {"grid", "time", "medium", "boundary", "attenuation", "source", "receiver", "receiver_line"},
      seis_text);
  const seismic::RunConfig rc = seismic::parse_run_config(seis_text, s.config, ".");
  if (!s.rig.empty()) cfg.rig = s.rig;
  cfg.output_dir = (std::filesystem::temp_directory_path() / ("insitu_study_" + std::to_string(::getpid()))).string();
  cfg.mode = insitu::OutputMode::overwrite;
  cfg.up = {0, 0, -1};
  seismic::Solver solver(rc.solver);
  const auto& g = rc.solver.grid;
  const render::GridGeometry grid{{g.nx, g.ny, g.nz}, {0, 0, 0}, {g.h, g.h, g.h}};
  raw_bytes = 2.0 * double(g.nx) * g.ny * g.nz * 4;
  insitu::Session session(cfg, grid, insitu::LocalBlock::whole(grid));
  const int tasks = session.task_count();
  std::map<int, std::vector<Image>> kept;
  session.set_frame_observer([&](int camera, int task, int, const Image& img) {
    if (camera % camera_step == 0) kept[camera * tasks + task].push_back(img);
  });
  solver.run(s.warmup_steps);
  auto input = [](const char* name, const seismic::FieldView& v) {
    return insitu::FieldInput{name, v.data, insitu::ScalarType::f32,
                              {1, std::int64_t(v.stride_y), std::int64_t(v.stride_z)}};
  };
  for (int n = 0; n < s.snapshots; ++n) {
    for (std::int64_t k = 0; k < cfg.schedule.every_steps; ++k) solver.step();
    solver.compute_derived();
    session.snapshot(solver.velocity_time(), {input("phi_p", solver.phi_p()), input("phi_s", solver.phi_s())});
    std::fprintf(stderr, "\rvideo study: %s snapshot %d/%d", s.config.c_str(), n + 1, s.snapshots);
  }
  std::fprintf(stderr, "\n");
  session.finalize();
  std::filesystem::remove_all(cfg.output_dir);
  std::vector<std::vector<Image>> out;
  for (auto& [id, frames] : kept) out.push_back(std::move(frames));
  return out;
}

double psnr_rgb(const Image& a, const Image& b) {
  double se = 0;
  std::size_t n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double d = double(a.row(y)[std::size_t(x) * a.channels + c]) - double(b.row(y)[std::size_t(x) * b.channels + c]);
        se += d * d;
        ++n;
      }
  return se == 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / (se / double(n)));
}

// Encodes the captured streams with one setting, all writers open at once and one flush per snapshot
// (as the session does), and prints a table row.
void study_row(const char* setting, const std::vector<std::vector<Image>>& streams, const video::VideoSettings& v,
               double raw_field_bytes_per_frame) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("insitu_study_movies_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const int w = streams[0][0].width, h = streams[0][0].height, frames = int(streams[0].size());
  ::malloc_trim(0);
  const std::int64_t rss0 = bench::resident_bytes();
  std::int64_t rss_max = rss0;
  double cpu = 0;
  {
    std::vector<std::unique_ptr<video::MovieWriter>> writers;
    for (std::size_t i = 0; i < streams.size(); ++i)
      writers.push_back(std::make_unique<video::MovieWriter>((dir / (std::to_string(i) + ".mp4")).string(), w, h, v));
    for (int f = 0; f < frames; ++f) {
      const double c0 = cpu_seconds();
      for (std::size_t i = 0; i < streams.size(); ++i) writers[i]->append(streams[i][std::size_t(f)]);
      for (auto& wr : writers) wr->flush();
      cpu += cpu_seconds() - c0;
      rss_max = std::max(rss_max, bench::resident_bytes());
    }
    for (auto& wr : writers) wr->close();
  }
  double bytes = 0, psnr_sum = 0, psnr_min = 99;
  for (std::size_t i = 0; i < streams.size(); ++i) {
    const std::string path = (dir / (std::to_string(i) + ".mp4")).string();
    bytes += double(std::filesystem::file_size(path));
    video::MovieReader r(path);
    r.set_crop(w, h);
    for (int f = 0; f < frames; ++f) {
      const double p = psnr_rgb(streams[i][std::size_t(f)], r.read_rgba(f));
      psnr_sum += p;
      psnr_min = std::min(psnr_min, p);
    }
  }
  std::filesystem::remove_all(dir);
  const double n = double(streams.size()) * frames;
  std::printf("| %s | %dx%d | %d | %d | %s | %.0f | %.1f | %.0f | %.1f / %.1f | %.2f |\n", setting, w, h, v.gop, v.crf,
              v.preset.c_str(), bytes / n, 100 * (bytes / n) / raw_field_bytes_per_frame, n / cpu, psnr_sum / n,
              psnr_min, double(rss_max - rss0) / double(streams.size()) / 1e6);
  std::fflush(stdout);
}

// `which`: "demo", "paper" or "" (both).
int video_study(const std::string& which) {
  const std::string src = PANOPTES_SOURCE_DIR;
  // The whole demo (24 snapshots), every 10th of its 130 cameras: 39 streams.
  std::vector<std::vector<Image>> demo, paper;
  double demo_raw = 0, quarter_raw = 0;
  if (which != "paper") demo = capture_frames({src + "/examples/demo.toml", "", 0, 24}, 10, demo_raw);
  // paper_quarter from the middle of the run: 4 of yinyang:2x2's 8 cameras, 20 snapshots, 920x896.
  if (which != "demo")
    paper = capture_frames({src + "/examples/paper_quarter.toml", "yinyang:2x2", 200, 20}, 2, quarter_raw);
  // Raw fields per camera-frame of the real runs (390 streams): the demo's grid, and the FULL paper
  // grid (256x512x160 = 64x the quarter grid's points) for the paper rows.
  demo_raw /= 390;
  const double paper_raw = 64 * quarter_raw / 390;
  std::printf("| setting | image | gop | crf | preset | bytes/frame | %% of raw fields | encode frames/CPU-s | PSNR dB mean / min | "
              "MB per open writer |\n|---|---|---|---|---|---|---|---|---|---|\n");
  struct V {
    int gop, crf;
    const char* preset;
  };
  const V variants[] = {{1, 20, "superfast"}, {10, 20, "superfast"}, {24, 20, "superfast"}, {10, 23, "superfast"},
                        {1, 23, "superfast"}, {1, 26, "superfast"},  {10, 26, "superfast"}, {1, 23, "veryfast"},
                        {10, 20, "ultrafast"}};
  for (const V& x : variants) {
    video::VideoSettings v;
    v.gop = x.gop;
    v.crf = x.crf;
    v.preset = x.preset;
    if (!demo.empty()) study_row("demo", demo, v, demo_raw);
  }
  for (const V& x : variants) {
    if (x.gop == 24 || paper.empty()) continue;
    video::VideoSettings v;
    v.gop = x.gop;
    v.crf = x.crf;
    v.preset = x.preset;
    study_row("paper", paper, v, paper_raw);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--video-study") == 0) {
      try {
        return video_study(i + 1 < argc ? argv[i + 1] : "");
      } catch (const std::exception& e) {
        std::fprintf(stderr, "insitu_bench: %s\n", e.what());
        return 1;
      }
    }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
