// Cameras inside the data (issue 14).
//
// BM_EquirectFrame: 360° x 180° frames at 1920x960 on the standard scene of render_bench (256x512x160
// spherical wave fronts, sample distance 0.5 voxel), the paper's 3 tasks (p, s, p+s) in one march, from
// a camera inside the volume (its centre) and from one outside (3 bounding radii).
//   frames_core_s   camera-frames (all 3 tasks) per core-second: frames / process CPU seconds
//   frames_s        the same per wall-second
//   psnr_db         the worst of the 3 task images against today's path (RenderOptions::equirect_adaptive
//                   off: every pixel marched), rendered once before the timed loop (issue 32)
// BM_DenseInside: issue 45's hard case, the same frame from inside a dense 128x256x80 field (waves
// everywhere, render::dense_wave_scene) with a volume of p, one of s and an isosurface of p, at the
// options of `panoptes render`; the full march in the same run for the PSNR and the speed-up.
//   frames_core_s (target >= 2), full_frames_core_s, speedup, psnr_db (target >= 45), marched_pct
//   iso_ref_psnr_db, iso_ref_speckles (and full_*: the full march's): the isosurface against the
//                   surface supersampled 4x4 (issue 41's speckle measure on this scene)
// BM_WalkLatency: switch latency when walking through a 4x4x3 lattice of 1920x960 360° streams (stamped
// synthetic database, gop 1 as in situ) at 30 fps with prefetch, 120 walks (one every 5th frame) along a
// pseudo-random route, paused or playing; the window draws the cut-out from the cached frame, so the
// switch is what the user waits for. Target p99 < 16 ms; with 120 walks p99 is the 2nd-worst walk.
//   walks, misses, refused   counts (refused: no camera that way, not a switch)
//   new_walks, new_hit_pct   walks to a (camera, frame) not shown before in the run, and their hit rate
// Paused, nothing moves: once the route has passed every camera, its frame is cached and a walk hits
// whatever the prefetcher does, so new_hit_pct (first visits) is the figure that tests the prefetch.
// BM_MissCost: what a miss costs on the display thread (reader open + 1920x960 keyframe decode).
#include <benchmark/benchmark.h>
#include <omp.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>
#include <thread>
#include <vector>

#include "core/image.hpp"
#include "player/engine.hpp"
#include "player/look.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "standard_scene.hpp"
#include "store/synthetic.hpp"

using namespace panoptes;
using namespace panoptes::render;
namespace fs = std::filesystem;

namespace {

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

const bench::StandardScene& scene() { return bench::standard_scene(); }

void equirect_frame(benchmark::State& state, bool full_march) {
  const auto& sc = scene();
  const bool inside = state.range(0) != 0;
  const Vec3 c = sc.grid.centre();
  const Vec3 eye = inside ? c : c + normalize(Vec3{-0.6, -0.7, 0.4}) * (3 * 0.5 * norm(sc.grid.domain_hi() - sc.grid.domain_lo()));
  const camera::Camera cam(eye, inside ? c + Vec3{0, 1, 0} : c, {0, 0, 1}, 60, 1920, 960, camera::Projection::equirectangular);
  const std::vector<TaskSpec> tasks{
      TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1)),
      TaskSpec::volume(1, TransferFunction::preset("s-wave"), ValueWindow::absolute(0, 1)),
      TaskSpec::volume2(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1), 1,
                        TransferFunction::preset("s-wave"), ValueWindow::absolute(0, 1))};
  std::vector<PartialImage> out(tasks.size());
  const auto finish = [&](std::vector<Image>& images) {
    images.clear();
    for (const PartialImage& o : out) images.push_back(finish_image(o, cam, sc.grid, {0, 0, 0}, OutlineStyle{false}));
  };
  std::vector<Image> full, images;
  RenderOptions every_pixel;
  every_pixel.equirect_adaptive = false;  // the renderer before issue 32's sampling on the sphere
  render_brick(cam, sc.fields, tasks, out, every_pixel);
  finish(full);
  const double cpu0 = process_cpu_seconds(), wall0 = omp_get_wtime();
  for (auto _ : state) {
    render_brick(cam, sc.fields, tasks, out, full_march ? every_pixel : RenderOptions{});  // defaults: what users get
    finish(images);
    benchmark::DoNotOptimize(images.data());
  }
  const double frames = double(state.iterations());
  state.counters["frames_core_s"] = frames / (process_cpu_seconds() - cpu0);
  state.counters["frames_s"] = frames / (omp_get_wtime() - wall0);
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < images.size(); ++t) worst = std::min(worst, psnr(images[t], full[t]));
  state.counters["psnr_db"] = std::min(worst, 999.0);  // identical images: +inf, shown as 999
}
void BM_EquirectFrame(benchmark::State& state) { equirect_frame(state, false); }
BENCHMARK(BM_EquirectFrame)->ArgName("inside")->Arg(1)->Arg(0)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
// The same frames by the full march (every pixel, RenderOptions::equirect_adaptive off): the renderer
// before issue 32, measured in the same run for the before/after ratio (psnr_db is then 999).
void BM_EquirectFrameFullMarch(benchmark::State& state) { equirect_frame(state, true); }
BENCHMARK(BM_EquirectFrameFullMarch)->ArgName("inside")->Arg(1)->Arg(0)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Issue 45 point 1: a 360° frame from inside a DENSE field, where nothing can be skipped.
// render::dense_wave_scene on 128x256x80 float32 points (waves fill the box), the eye at the domain's
// centre looking along +y, 1920x960 equirectangular, 3 tasks in one march: a p-wave volume of p, an
// s-wave volume of s, an isosurface of p at 0.3 of p's window; windows the 99.9th percentile of |v| as
// the session sets them. Options as `panoptes render` sets them (0.5 voxel, adaptive sampling on,
// isosurface anti-aliasing on). The full march (every pixel: equirect_adaptive and adaptive off) is
// rendered in the same run, alternately with the fast path, for the PSNR and the ratio.
struct DenseInside {
  GridGeometry grid{{128, 256, 80}, {0, 0, 0}, {1, 1, 1}};
  DenseWaveScene waves = dense_wave_scene(grid);
  std::vector<TaskSpec> tasks;
  std::vector<PreparedField> fields;
  DenseInside() {
    const std::vector<FieldView> views{FieldView::whole(grid, waves.p.data()), FieldView::whole(grid, waves.s.data())};
    const double rp = abs_percentile(views[0], 0.999), rs = abs_percentile(views[1], 0.999);
    tasks = {TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, rp)),
             TaskSpec::volume(1, TransferFunction::preset("s-wave"), ValueWindow::absolute(0, rs)),
             TaskSpec::isosurface(0, float(0.3 * rp))};
    fields = prepare_fields(views, tasks);  // as the in-situ session prepares them
  }
};

// Issue 41's speckle measure on BM_DenseInside's isosurface (task 2): the surface supersampled 4x4
// (anti-aliasing off, 0.125-voxel steps, every sub-pixel marched; ~30 CPU-s, once per process),
// box-filtered to 1920x960 and rounded to 8 bits over black, as IsoEdges.SpecklesAgainstTheSupersampledSurface
// builds its reference. A speckle: a pixel the reference covers whose colour lies more than 30 levels
// outside the reference's range over the pixel and its eight neighbours in some channel.
struct SupersampledIso {
  Image rgb;                        // the box-filtered reference over black
  std::vector<std::uint8_t> cover;  // some sub-pixel meets the surface
  // The camera of BM_DenseInside (eye, look-at point, up) at W x H.
  SupersampledIso(const DenseInside& sc, const Vec3& eye, const Vec3& at, const Vec3& up, int W, int H) {
    constexpr int S = 4;
    const camera::Camera fine(eye, at, up, 60, W * S, H * S, camera::Projection::equirectangular);
    RenderOptions o;
    o.equirect_adaptive = false;
    o.sample_distance = 0.125;
    const std::vector<TaskSpec> iso{sc.tasks[2]};
    std::vector<PartialImage> out(1);
    render_brick(fine, sc.fields, iso, out, o);
    rgb = Image(W, H, 4);
    cover.assign(std::size_t(W) * std::size_t(H), 0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        double sum[3] = {0, 0, 0};
        bool any = false;
        for (int j = 0; j < S; ++j)
          for (int i = 0; i < S; ++i) {
            const float* p = out[0].rgba_at(S * x + i, S * y + j);
            for (int c = 0; c < 3; ++c) sum[c] += p[c];
            any = any || p[3] > 0;
          }
        for (int c = 0; c < 3; ++c) rgb.at(x, y)[c] = std::uint8_t(std::clamp(std::lround(255 * sum[c] / (S * S)), 0L, 255L));
        rgb.at(x, y)[3] = 255;
        cover[std::size_t(y) * std::size_t(W) + std::size_t(x)] = any;
      }
  }
  int speckles(const Image& img) const {
    int n = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        if (!cover[std::size_t(y) * std::size_t(img.width) + std::size_t(x)]) continue;
        bool off = false;
        for (int c = 0; c < 3 && !off; ++c) {
          int lo = 255, hi = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int v = rgb.at(std::clamp(x + dx, 0, img.width - 1), std::clamp(y + dy, 0, img.height - 1))[c];
              lo = std::min(lo, v), hi = std::max(hi, v);
            }
          const int v = img.at(x, y)[c];
          off = v < lo - 30 || v > hi + 30;
        }
        n += off;
      }
    return n;
  }
};

void BM_DenseInside(benchmark::State& state) {
  static const DenseInside sc;
  const Vec3 c = sc.grid.centre();
  const camera::Camera cam(c, c + Vec3{0, 1, 0}, {0, 0, 1}, 60, 1920, 960, camera::Projection::equirectangular);
  RenderOptions fast;  // what `panoptes render` and the in-situ session use
  fast.adaptive = true;
  fast.iso_antialias = true;
  RenderOptions full = fast;  // every pixel marched
  full.adaptive = false;
  full.equirect_adaptive = false;
  // Each path keeps its partial and final images, as the session reuses its buffers: allocating
  // 3 x 29 MB of partial images per frame would measure page faults, not the renderer.
  std::vector<PartialImage> out_full(sc.tasks.size()), out_fast(sc.tasks.size());
  std::vector<Image> full_images(sc.tasks.size()), images(sc.tasks.size());
  const auto render = [&](const RenderOptions& o, std::vector<PartialImage>& out, std::vector<Image>& finished) {
    const RenderStats st = render_brick(cam, sc.fields, sc.tasks, out, o);
    for (std::size_t t = 0; t < out.size(); ++t)
      finish_image_into(out[t], cam, sc.grid, finished[t], {0, 0, 0}, OutlineStyle{false});
    return st;
  };
  render(full, out_full, full_images);  // first touch of both paths' buffers, outside the timing
  render(fast, out_fast, images);
  RenderStats st_fast;
  // Per iteration one full march (3-4 CPU-s) and kFast frames of the fast path, so that the fast
  // path's figure, a fraction of a second per frame, is not one frame's noise on the shared machine.
  constexpr int kFast = 4;
  double cpu_fast = 0, cpu_full = 0;
  for (auto _ : state) {
    double c0 = process_cpu_seconds();
    render(full, out_full, full_images);
    cpu_full += process_cpu_seconds() - c0;
    c0 = process_cpu_seconds();
    for (int r = 0; r < kFast; ++r) st_fast = render(fast, out_fast, images);
    cpu_fast += process_cpu_seconds() - c0;
    benchmark::DoNotOptimize(images.data());
  }
  const double frames = double(state.iterations());
  state.counters["frames_core_s"] = kFast * frames / cpu_fast;  // target >= 2
  state.counters["full_frames_core_s"] = frames / cpu_full;
  state.counters["speedup"] = cpu_full / (cpu_fast / kFast);
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < images.size(); ++t) worst = std::min(worst, psnr(images[t], full_images[t]));
  state.counters["psnr_db"] = std::min(worst, 999.0);  // target >= 45
  state.counters["marched_pct"] = 100.0 * double(st_fast.rays) / double(st_fast.rays + st_fast.interpolated_pixels);
  state.counters["marched_per_ray"] = double(st_fast.marched_samples) / double(std::max<std::uint64_t>(1, st_fast.rays));
  // The isosurface against the supersampled surface (not timed): the fast frame and the full march.
  static const SupersampledIso ref(sc, c, c + Vec3{0, 1, 0}, {0, 0, 1}, cam.width(), cam.height());
  state.counters["iso_ref_psnr_db"] = psnr(images[2], ref.rgb);
  state.counters["iso_ref_speckles"] = ref.speckles(images[2]);
  state.counters["full_iso_ref_psnr_db"] = psnr(full_images[2], ref.rgb);
  state.counters["full_iso_ref_speckles"] = ref.speckles(full_images[2]);
}
BENCHMARK(BM_DenseInside)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

const fs::path& lattice_db() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / "panoptes_inside_bench_lattice";
    if (!fs::exists(d / "panoptes.json")) {
      store::SyntheticOptions o;
      o.lattice = {4, 4, 3};
      o.projection = "equirectangular";
      o.tasks = 1;
      o.frames = 12;
      o.width = 1920, o.height = 960;
      o.video.gop = 1;  // as the in-situ writers: every frame is a keyframe
      o.overwrite = true;
      store::write_synthetic_database(d, o);
    }
    return d;
  }();
  return dir;
}

// One walk per `kWalkEvery` display frames for kTicks frames, along a pseudo-random route (fixed seed)
// through the whole lattice: a yaw of 0/90/180/-90 degrees, then forward (3 in 5), up or down; a walk
// the lattice does not allow tries the next choice. Misses are listed on stderr (which walk, which
// camera, which frame, whether a prefetch decode was in flight).
void BM_WalkLatency(benchmark::State& state) {
  const fs::path& db = lattice_db();
  constexpr int kTicks = 600, kWalkEvery = 5;  // 20 s at 30 fps, 120 walks
  std::vector<double> latencies;
  std::int64_t hits = 0, switches = 0, refused = 0, first_visits = 0, first_visit_hits = 0;
  for (auto _ : state) {
    player::EngineOptions o;
    o.prefetch_threads = 2;
    o.start_playing = state.range(0) != 0;
    player::Engine engine(db, o);
    engine.current_frame();
    player::Look look;
    std::uint32_t rng = 12345;
    const auto next = [&] { return (rng = rng * 1664525u + 1013904223u) >> 8; };
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < kTicks; ++k) {
      std::this_thread::sleep_until(start + std::chrono::microseconds(k * 1000000LL / 30));
      engine.tick();
      if (k % kWalkEvery == 2) {
        const std::uint32_t r = next();
        bool walked = false;
        for (int attempt = 0; attempt < 20 && !walked; ++attempt) {
          const std::uint32_t c = (r + std::uint32_t(attempt) * 7u) % 20u;  // yaw: c % 4, move: c / 4
          static constexpr player::Walk moves[] = {player::Walk::forward, player::Walk::forward, player::Walk::forward,
                                                   player::Walk::up, player::Walk::down};
          player::Look l = look;
          l.yaw_deg = 90.0 * double(c % 4) - (c % 4 == 3 ? 360.0 : 0.0);
          l.pitch_deg = 0;
          if (player::walk_target(engine.manifest(), engine.selection().camera, l, moves[c / 4]) < 0) continue;
          look = l;
          walked = player::walk_keeping_view(engine, look, moves[c / 4]);
        }
        if (!walked) ++refused;
      }
      benchmark::DoNotOptimize(engine.current_frame());
    }
    const auto st = engine.statistics();
    std::set<std::pair<int, int>> seen{{0, 0}};  // (camera, frame) shown before
    for (std::size_t i = 0; i < st.switches.size(); ++i) {
      const auto& w = st.switches[i];
      latencies.push_back(w.latency_ms);
      hits += w.cache_hit;
      ++switches;
      if (seen.insert({w.to.camera, w.to.frame}).second) {
        ++first_visits;
        first_visit_hits += w.cache_hit;
      }
      if (!w.cache_hit)
        std::fprintf(stderr, "  miss: walk %zu camera %d -> %d frame %d: %.2f ms\n", i + 1, w.from.camera, w.to.camera,
                     w.to.frame, w.latency_ms);
    }
  }
  const player::Summary s = player::summarize(latencies);
  state.counters["walks"] = double(switches);
  state.counters["misses"] = double(switches - hits);
  state.counters["refused"] = double(refused);
  state.counters["walk_hit_pct"] = switches ? 100.0 * double(hits) / double(switches) : 0;
  // Walks to a (camera, frame) not shown before in the run: the prefetcher's real test (a revisit may
  // hit simply because the frame is still cached).
  state.counters["new_walks"] = double(first_visits);
  state.counters["new_hit_pct"] = first_visits ? 100.0 * double(first_visit_hits) / double(first_visits) : 0;
  state.counters["walk_p50_ms"] = s.p50;
  state.counters["walk_p99_ms"] = s.p99;
  state.counters["walk_max_ms"] = s.max;
}
// playing:0 = looking around while paused (the prefetcher decodes the neighbours' current frame, the
// camera ahead first); playing:1 = walking while time plays at 30 fps (every neighbour's next frame
// must be decoded within one display period: 6 x 30 decodes of 1920x960 per second exceed 2 cores).
BENCHMARK(BM_WalkLatency)->ArgName("playing")->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kSecond);

// What a miss costs: switching with prefetch off through all 48 cameras (a reader is opened and a
// 1920x960 keyframe decoded on the display thread), then decoding frame 3 of each with its reader open.
void BM_MissCost(benchmark::State& state) {
  const fs::path& db = lattice_db();
  std::vector<double> cold, warm;
  for (auto _ : state) {
    player::EngineOptions o;
    o.prefetch = false;
    o.start_playing = false;
    o.reader_pool_capacity = 64;  // every camera's reader stays open for the second loop
    player::Engine engine(db, o);
    engine.current_frame();
    const int n = engine.manifest().camera_count();
    for (int c = 1; c < n; ++c) {
      engine.jump_to_camera(c);
      engine.current_frame();
    }
    for (const auto& w : engine.statistics().switches) cold.push_back(w.latency_ms);
    for (int c = 0; c < n; ++c) {
      const auto t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(engine.frame_at({c, 0, 3}));
      warm.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  const player::Summary a = player::summarize(cold), b = player::summarize(warm);
  state.counters["open_decode_p50_ms"] = a.p50;
  state.counters["open_decode_max_ms"] = a.max;
  state.counters["decode_p50_ms"] = b.p50;
  state.counters["decode_max_ms"] = b.max;
}
BENCHMARK(BM_MissCost)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
