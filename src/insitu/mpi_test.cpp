// MPI test of the in-situ session (run by ctest under mpiexec with 1, 2 and 3 ranks).
//   insitu_mpi_test write DIR   — renders a known field (slabs along z, double data without ghosts for
//       one field, float data with 2 ghost layers for the other) and checks every finished frame on its
//       owner rank against the same field rendered directly on the whole grid (max difference ≤ 1/255).
//   insitu_mpi_test refusals DIR — one rank's bad fields are refused by every rank, without a hang.
//   insitu_mpi_test waits DIR — a rank arriving late at every step's agreement leaves the waiting ranks'
//       timer slack as it was (the wait sleeps with a fine slack, rank_agreement.cpp).
//   insitu_mpi_test compare DIR1 DIR2...  — every database is complete and every frame of every stream
//       matches the first database's with PSNR ≥ 45 dB (rank independence).
#include <mpi.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "insitu/session.hpp"
#include "camera/rig_spec.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "store/database.hpp"
#include "insitu/mpi_test_support.hpp"

using namespace panoptes;

namespace {

render::GridGeometry test_grid() { return {{33, 29, 26}, {0, 0, 0}, {1, 1, 1.2}}; }

std::vector<float> field_a(const render::GridGeometry& g, double t) {
  const std::vector<render::WaveFront> fronts{{g.centre(), 6 + 3 * t, 2.5, 1.0},
                                               {g.centre() + Vec3{5, -3, 2}, 4 + 2 * t, 2.0, -0.6}};
  return render::wave_field(g, fronts);
}
std::vector<float> field_b(const render::GridGeometry& g, double t) {
  std::vector<float> a = field_a(g, t + 0.5);
  for (float& v : a) v = std::fabs(v) * 0.8f;
  return a;
}

const char* kConfig = R"(
[output]
title = "insitu mpi test"
overwrite = true
[image]
width = 48
height = 40
[rig]
spec = "fibonacci:5"
[schedule]
every_steps = 2
[video]
crf = 10
[render]
adaptive = false  # compared pixel for pixel with direct renders of each task alone (adaptive sampling refines where any task of the march does)
[[task]]
name = "a hot"
type = "volume"
field = "a"
preset = "hot"
relative = false
window = [0.0, 0.8]
extinction_scale = 2.0
[[task]]
name = "a iso"
type = "isosurface"
field = "a"
isovalues = [0.3, 0.6]
[[task]]
name = "b slice"
type = "slice"
field = "b"
axis = "y"
position = 0.4
relative = false
window = [0.0, 1.0]
preset = "rainbow"
[[task]]
name = "both"
type = "volume2"
fields = ["a", "b"]
window = [0.0, 1.0]
window2 = [0.0, 1.0]
)";

// split: [resources] parallel. With the cameras split (the default here: 5 cameras, small grid) each
// rank renders whole rays, so its frames must EQUAL the direct whole-grid rendering; bricks are
// composited and may differ by one level.
int write(const std::string& dir, const std::string& split) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  insitu::SessionConfig cfg = insitu::parse_session_config_text(kConfig, "mpi_test config");
  cfg.output_dir = dir;
  cfg.parallel = insitu::parse_render_split(split);
  const bool whole_rays = size == 1 || cfg.parallel != insitu::RenderSplit::bricks;
  const render::GridGeometry g = test_grid();
  const insitu::LocalBlock blk_a = insitu::LocalBlock::slab(g, 2, size, rank, 0);
  const insitu::LocalBlock blk_b = insitu::LocalBlock::slab(g, 2, size, rank, 2);
  // The session takes ONE block description (ghost widths) for all fields; field b is handed with a
  // stride over its own ghosted array, starting at its first owned point.
  insitu::Session session(cfg, g, blk_a, MPI_COMM_WORLD);
  int failures = 0;
  int checked = 0;
  std::vector<float> whole_a, whole_b;
  std::vector<render::PartialImage> direct;
  session.set_frame_observer([&](int camera, int task, int, const Image& img) {
    // Tasks 0..2 (absolute windows / isovalues) must equal the direct whole-grid rendering.
    if (task == 4) return;  // volume2 with relative windows: compared across rank counts only
    const std::vector<render::PreparedField> fields{render::PreparedField(render::FieldView::whole(g, whole_a.data())),
                                                   render::PreparedField(render::FieldView::whole(g, whole_b.data()))};
    render::TaskSpec spec;
    if (task == 0)
      spec = render::TaskSpec::volume(0, render::TransferFunction::preset("hot", 2.0f),
                                      render::ValueWindow::absolute(0, 0.8));
    else if (task == 1 || task == 2)
      spec = render::TaskSpec::isosurface(0, task == 1 ? 0.3f : 0.6f);
    else
      spec = render::TaskSpec::slice(1, 1, 0.4 * 28, render::TransferFunction::preset("rainbow"),
                                     render::ValueWindow::absolute(0, 1));
    direct.resize(1);
    const camera::Camera cam = camera::make_rig("fibonacci:5", camera::Domain{g.domain_lo(), g.domain_hi() - g.domain_lo()})
                                   .camera(camera, 48, 40);
    render::render_brick(cam, fields, std::span<const render::TaskSpec>(&spec, 1), direct, cfg.render);  // the session's options (iso_antialias)
    const Image ref = render::finish_image(direct[0], cam, g);
    int maxdiff = 0;
    for (std::size_t i = 0; i < ref.pixels.size(); ++i)
      maxdiff = std::max(maxdiff, std::abs(int(ref.pixels[i]) - int(img.pixels[i])));
    ++checked;
    if (maxdiff > (whole_rays ? 0 : 1)) {
      std::fprintf(stderr, "rank %d: camera %d task %d differs from the direct rendering by %d/255\n", rank, camera,
                   task, maxdiff);
      ++failures;
    }
  });
  for (int step = 0; step < 5; ++step) {
    const double t = 0.5 * step;
    whole_a = field_a(g, t);
    whole_b = field_b(g, t);
    // Local copies: a as double without ghosts, b as float with its ghost layers.
    std::vector<double> a;
    for (int k = blk_a.offset[2]; k < blk_a.offset[2] + blk_a.extent[2]; ++k)
      for (int j = 0; j < g.dims[1]; ++j)
        for (int i = 0; i < g.dims[0]; ++i)
          a.push_back(whole_a[std::size_t((std::int64_t(k) * g.dims[1] + j) * g.dims[0] + i)]);
    const int k0 = blk_b.offset[2] - blk_b.ghost_lo[2];
    const int k1 = blk_b.offset[2] + blk_b.extent[2] + blk_b.ghost_hi[2];
    std::vector<float> b(whole_b.begin() + std::ptrdiff_t(k0) * g.dims[0] * g.dims[1],
                         whole_b.begin() + std::ptrdiff_t(k1) * g.dims[0] * g.dims[1]);
    const std::int64_t plane = std::int64_t(g.dims[0]) * g.dims[1];
    const std::vector<insitu::FieldInput> inputs{
        {"a", a.data(), insitu::ScalarType::f64, {0, 0, 0}},
        {"b", b.data() + blk_b.ghost_lo[2] * plane, insitu::ScalarType::f32, {1, g.dims[0], plane}}};
    session.process(step, t, inputs);
  }
  session.finalize();
  const insitu::SessionStats st = session.reduced_stats();
  int total_fail = 0, total_checked = 0;
  MPI_Allreduce(&failures, &total_fail, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&checked, &total_checked, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) {
    const store::Database db = store::Database::open(dir);
    std::printf("%d ranks (split %s): %d snapshots, %lld frames encoded, %d checked against direct rendering, %d failures; "
                "render %.3f s composite %.3f s encode %.3f s\n",
                size, split.c_str(), st.snapshots, (long long)st.frames_encoded, total_checked, total_fail, st.time.render,
                st.time.composite, st.time.encode);
    if (db.status() != store::Status::complete || db.frame_count() != 3 || db.task_count() != 5 ||
        db.camera_count() != 5) {
      std::fprintf(stderr, "database %s: status %s, %d frames, %d tasks, %d cameras; expected complete, 3, 5, 5\n",
                   dir.c_str(), std::string(store::to_string(db.status())).c_str(), db.frame_count(), db.task_count(),
                   db.camera_count());
      return 1;
    }
    if (total_checked != 3 * 5 * 4) {
      std::fprintf(stderr, "expected %d frames checked, got %d\n", 3 * 5 * 4, total_checked);
      return 1;
    }
  }
  return total_fail == 0 ? 0 : 1;
}

int compare(const std::vector<std::string>& dirs) { return insitu_test::compare_databases(dirs, "in situ"); }

// This rank's slab (along z, 2 ghost layers) of the test grid with constant fields a (0.5) and b (0.25),
// for the tests of the calls rather than the pictures.
struct ConstantSlab {
  int rank = 0, size = 1;
  render::GridGeometry g = test_grid();
  insitu::SessionConfig cfg;
  insitu::LocalBlock block;
  std::vector<float> a, b;
  std::int64_t first = 0;  // the first owned point
  ConstantSlab(const std::string& dir, const char* name) {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    cfg = insitu::parse_session_config_text(kConfig, name);
    cfg.output_dir = dir;
    block = insitu::LocalBlock::slab(g, 2, size, rank, 2);
    const std::int64_t nz = block.extent[2] + block.ghost_lo[2] + block.ghost_hi[2];
    a.assign(std::size_t(g.dims[0] * g.dims[1] * nz), 0.5f);
    b.assign(a.size(), 0.25f);
    first = block.ghost_lo[2] * g.dims[0] * g.dims[1];
  }
  insitu::FieldInput field_a() const { return {"a", a.data() + first, insitu::ScalarType::f32, {0, 0, 0}}; }
  insitu::FieldInput field_b() const { return {"b", b.data() + first, insitu::ScalarType::f32, {0, 0, 0}}; }
};

// Refusals of one rank's own arguments (issue 42): rank 1 hands a field whose stride of 2^62 floats
// overflows 64-bit offsets, then omits a field, then gives a NaN time to process() on a due step, then
// a time that does not increase; every rank must refuse each snapshot (before, the refusing rank left
// and the others waited for it in the snapshot's collectives: this test timed out), nothing is
// written, and the same session then takes good snapshots.
int refusals(const std::string& dir) {
  const ConstantSlab c(dir, "mpi refusals");
  const int rank = c.rank, size = c.size;
  const insitu::FieldInput good_a = c.field_a(), good_b = c.field_b();
  const insitu::FieldInput huge_b{"b", c.b.data() + c.first, insitu::ScalarType::f32, {1, c.g.dims[0], std::int64_t(1) << 62}};
  insitu::Session s(c.cfg, c.g, c.block, MPI_COMM_WORLD);
  int failures = 0;
  auto expect_refused = [&](const std::vector<insitu::FieldInput>& fields, const std::string& want, double t,
                            bool process = false) {
    try {
      if (process)
        s.process(0, t, fields);
      else
        s.snapshot(t, fields);
      std::fprintf(stderr, "rank %d: FAIL: the snapshot at %g was taken\n", rank, t);
      ++failures;
    } catch (const Error& e) {
      const std::string what = e.what();
      if (what.find(want) == std::string::npos) {
        std::fprintf(stderr, "rank %d: FAIL: \"%s\" does not say \"%s\"\n", rank, what.c_str(), want.c_str());
        ++failures;
      }
    }
  };
  const bool bad = rank == 1 % size;  // rank 1, or rank 0 alone
  const std::string other = "rank 1 refused";
  expect_refused({good_a, bad ? huge_b : good_b}, bad ? "reach further than 64-bit offsets" : other, 0);
  if (bad) expect_refused({good_a}, "field \"b\" (read by a task) was not given", 0);
  else expect_refused({good_a, good_b}, other, 0);
  expect_refused({good_a, good_b}, bad ? "time nan; expected a finite" : other, bad ? NAN : 0.0, true);
  if (s.snapshots() != 0) ++failures;
  s.snapshot(0, {good_a, good_b});
  expect_refused({good_a, good_b}, bad ? "time 0 is not after the previous snapshot's time 0" : other, bad ? 0.0 : 1.0);
  s.snapshot(1, {good_a, good_b});
  s.finalize();
  if (rank == 0) {
    const auto db = store::Database::open(dir);
    if (db.frame_count() != 2 || db.status() != store::Status::complete) ++failures;
  }
  int all = failures;
  MPI_Allreduce(&failures, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) std::printf("refusals: %s\n", all ? "FAILED" : "every rank refused each bad snapshot; the good one was taken");
  return all ? 1 : 0;
}

// The agreement's wait sleeps with a 1 us timer slack and must hand the simulation's thread back its
// own: rank 1 comes 5 ms late to each step's process(), so rank 0 waits past the spin into the sleeps.
int waits(const std::string& dir) {
  const ConstantSlab c(dir, "mpi waits");
  const int rank = c.rank, size = c.size;
  const std::vector<insitu::FieldInput> fields{c.field_a(), c.field_b()};
  int failures = 0;
#ifdef __linux__
  const unsigned long mine = 77000;  // ns: not the default, not the wait's own
  prctl(PR_SET_TIMERSLACK, mine, 0, 0, 0);
#endif
  insitu::Session s(c.cfg, c.g, c.block, MPI_COMM_WORLD);
  double waited = 0;
  for (int step = 0; step < 6; ++step) {
    if (rank == 1) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    const auto t0 = std::chrono::steady_clock::now();
    s.process(step, 0.1 * step, fields);
    waited += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
#ifdef __linux__
    const long now = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
    if (now != long(mine)) {
      std::fprintf(stderr, "rank %d: FAIL: timer slack %ld ns after step %d's process(); expected %lu ns (the caller's)\n",
                   rank, now, step, mine);
      ++failures;
    }
#endif
  }
  s.finalize();
  // Rank 0 did wait (else the test saw no sleep): ~5 ms per step, less the steps' own work.
  if (rank == 0 && size > 1 && waited < 6 * 0.002) {
    std::fprintf(stderr, "rank 0: FAIL: waited only %.4f s in 6 process() calls behind a rank 5 ms late\n", waited);
    ++failures;
  }
  int all = failures;
  MPI_Allreduce(&failures, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) std::printf("waits: %s (rank 0 waited %.3f s)\n", all ? "FAILED" : "every rank's timer slack is its own after waiting", waited);
  return all ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rc = 2;
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && (argc == 3 || argc == 4)) rc = write(argv[2], argc == 4 ? argv[3] : "auto");
    else if (mode == "refusals" && argc == 3) rc = refusals(argv[2]);
    else if (mode == "waits" && argc == 3) rc = waits(argv[2]);
    else if (mode == "compare" && argc >= 4) rc = compare(std::vector<std::string>(argv + 2, argv + argc));
    else std::fprintf(stderr, "usage: insitu_mpi_test write DIR [auto|cameras|bricks] | refusals DIR | waits DIR | compare DIR1 DIR2...\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "insitu_mpi_test: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
