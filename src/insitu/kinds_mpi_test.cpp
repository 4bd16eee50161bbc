// Rank independence of EVERY task kind (issue 43; DESIGN.md decision 14): one [[task]] table per
// render::kTaskKinds entry, rendered by 1-4 ranks (z slabs: one brick per rank), each frame compared
// on its owner rank with the same task rendered directly on the whole grid before encoding (max
// difference <= 1/255), and the databases of all rank counts with each other (PSNR >= 45 dB after
// H.264). A kind added to the enum without a table here fails at once ("no table for kind ...").
//   insitu_kinds_mpi_test write DIR [RIG]    (under mpiexec -np 1..4; RIG replaces fibonacci:6, e.g. a
//                                            rig of fewer cameras than ranks: band compositing)
//   insitu_kinds_mpi_test compare DIR1 DIR2...
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "insitu/session.hpp"
#include "insitu/task_plan.hpp"
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

// A table per kind, with absolute windows and values (the direct rendering needs no reference).
// Empty for a kind that has none yet: the test then fails and says which.
std::string task_table(render::TaskKind k) {
  switch (k) {
    case render::TaskKind::volume:
      return "[[task]]\nname = \"volume\"\ntype = \"volume\"\nfield = \"a\"\npreset = \"p-wave\"\nrelative = false\n"
             "window = [0.0, 0.8]\nextinction_scale = 2.0\n";
    case render::TaskKind::isosurface:
      return "[[task]]\nname = \"iso\"\ntype = \"isosurface\"\nfield = \"a\"\nisovalues = [0.3, -0.2]\n";
    case render::TaskKind::slice:
      return "[[task]]\nname = \"slice\"\ntype = \"slice\"\nfield = \"a\"\naxis = \"z\"\nposition = 0.45\n"
             "relative = false\nwindow = [-1.0, 1.0]\n";
    case render::TaskKind::mip:
      return "[[task]]\nname = \"mip\"\ntype = \"mip\"\nfield = \"a\"\npreset = \"hot\"\nrelative = false\n"
             "window = [0.1, 0.9]\n[[task]]\nname = \"mip signed\"\ntype = \"mip\"\nfield = \"a\"\n"
             "preset = \"diverging\"\nrelative = false\nwindow = [-1.0, 1.0]\n";
  }
  return "";
}

std::string config_text() {
  std::string s = "[output]\ntitle = \"every kind\"\nmode = \"overwrite\"\n[image]\nwidth = 48\nheight = 40\n"
                  "[rig]\nspec = \"fibonacci:6\"\n[schedule]\nevery_steps = 1\n[video]\ncrf = 10\n"
                  "[render]\niso_antialias = true\nadaptive = false\n";  // compared pixel for pixel with direct renders
  for (render::TaskKind k : render::kTaskKinds) {
    const std::string t = task_table(k);
    if (t.empty()) throw Error(std::string("no table for kind ") + render::to_string(k) + " in kinds_mpi_test.cpp");
    s += t;
  }
  return s;
}

int write(const std::string& dir, const std::string& rig_spec) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  insitu::SessionConfig cfg = insitu::parse_session_config_text(config_text(), "kinds_mpi_test config");
  cfg.output_dir = dir;
  if (!rig_spec.empty()) cfg.rig = rig_spec;
  const render::GridGeometry g = test_grid();
  const insitu::LocalBlock blk = insitu::LocalBlock::slab(g, 2, size, rank, 0);
  // The renderer's tasks as the session plans them (absolute windows: no reference to resolve).
  const insitu::TaskPlan plan(cfg.tasks, g);
  std::vector<render::TaskSpec> specs;
  plan.resolve(std::vector<double>(plan.field_names().size(), 1.0), specs);
  insitu::Session session(cfg, g, blk, MPI_COMM_WORLD);
  std::vector<float> whole;
  int failures = 0, checked = 0;
  std::vector<int> checked_kind(render::kTaskKinds.size(), 0);
  std::vector<render::PartialImage> direct(1);
  const camera::Rig rig = camera::make_rig(cfg.rig, camera::Domain{g.domain_lo(), g.domain_hi() - g.domain_lo()});
  session.set_frame_observer([&](int camera, int task, int, const Image& img) {
    const render::TaskSpec& spec = specs[std::size_t(task)];
    const std::vector<render::PreparedField> fields{render::PreparedField(render::FieldView::whole(g, whole.data()))};
    const camera::Camera cam = rig.camera(camera, cfg.width, cfg.height);
    render::render_brick(cam, fields, std::span<const render::TaskSpec>(&spec, 1), direct, cfg.render);
    const Image ref = render::finish_image(direct[0], cam, g);
    int maxdiff = 0;
    for (std::size_t i = 0; i < ref.pixels.size(); ++i)
      maxdiff = std::max(maxdiff, std::abs(int(ref.pixels[i]) - int(img.pixels[i])));
    ++checked;
    for (std::size_t k = 0; k < render::kTaskKinds.size(); ++k) checked_kind[k] += render::kTaskKinds[k] == spec.kind;
    if (maxdiff > 1) {
      std::fprintf(stderr, "rank %d of %d: camera %d task %d (%s) differs from the whole-grid rendering by %d/255\n",
                   rank, size, camera, task, render::to_string(spec.kind), maxdiff);
      ++failures;
    }
  });
  for (int step = 0; step < 2; ++step) {
    const double t = 0.7 * step;
    whole = field_a(g, t);
    const std::size_t plane = std::size_t(g.dims[0]) * std::size_t(g.dims[1]);
    const std::vector<float> local(whole.begin() + std::ptrdiff_t(std::size_t(blk.offset[2]) * plane),
                                   whole.begin() + std::ptrdiff_t(std::size_t(blk.offset[2] + blk.extent[2]) * plane));
    session.process(step, t, {{"a", local.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }
  session.finalize();
  std::vector<int> all_kind(checked_kind.size(), 0);
  int all_fail = 0, all_checked = 0;
  MPI_Allreduce(&failures, &all_fail, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&checked, &all_checked, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(checked_kind.data(), all_kind.data(), int(all_kind.size()), MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank != 0) return all_fail == 0 ? 0 : 1;
  const int expected = 2 * rig.size() * int(plan.size());
  std::printf("%d rank(s): %d frames checked against the whole-grid rendering, %d differ by more than 1/255;", size,
              all_checked, all_fail);
  for (std::size_t k = 0; k < all_kind.size(); ++k) std::printf(" %s %d", render::to_string(render::kTaskKinds[k]), all_kind[k]);
  std::printf("\n");
  if (all_checked != expected) {
    std::fprintf(stderr, "expected %d frames checked, got %d\n", expected, all_checked);
    return 1;
  }
  for (std::size_t k = 0; k < all_kind.size(); ++k)
    if (all_kind[k] == 0) {
      std::fprintf(stderr, "kind %s was not rendered\n", render::to_string(render::kTaskKinds[k]));
      return 1;
    }
  const store::Database db = store::Database::open(dir);
  if (db.status() != store::Status::complete || db.frame_count() != 2 || db.task_count() != int(plan.size())) {
    std::fprintf(stderr, "database %s: not complete with 2 frames of %zu tasks\n", dir.c_str(), plan.size());
    return 1;
  }
  return all_fail == 0 ? 0 : 1;
}

int compare(const std::vector<std::string>& dirs) { return insitu_test::compare_databases(dirs, "every kind"); }

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rc = 2;
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && (argc == 3 || argc == 4)) rc = write(argv[2], argc == 4 ? argv[3] : "");
    else if (mode == "compare" && argc >= 4) rc = compare(std::vector<std::string>(argv + 2, argv + argc));
    else std::fprintf(stderr, "usage: insitu_kinds_mpi_test write DIR [RIG] | compare DIR1 DIR2...\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "insitu_kinds_mpi_test: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
