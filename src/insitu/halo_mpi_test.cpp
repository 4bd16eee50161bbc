// MPI test of halos as simulation codes have them (issue 28): ranks decomposed in 2-D and 3-D hand the
// session arrays whose edge and corner ghosts, and stored layers beyond the valid ones, hold stale
// garbage (1e30, NaN), as after a face-only halo exchange. Every finished frame must equal the
// whole-grid rendering (≤ 1/255 per channel, like insitu.mpi_write_*), and every decoded frame the
// 1-rank database's.
//   halo_mpi_test write DIR LAYOUT   — LAYOUT: 1 (1 rank), 2x2 (4 ranks: 3 ghost layers stored, 2 valid,
//       faces only), 2x1x2 (4 ranks: 2 stored, 1 valid: the rest is fetched), 3u (3 ranks of unequal
//       boxes: 2 stored, all valid, faces only), 2x2full (4 ranks, a full 26-neighbour exchange:
//       edges_valid, nothing fetched)
//   halo_mpi_test compare DIR1 DIR2...  — decoded frames of every database against the first's.
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "insitu/session.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "store/database.hpp"

using namespace panoptes;

namespace {

render::GridGeometry test_grid() { return {{24, 21, 18}, {0, 0, 0}, {1, 1, 1.1}}; }

std::vector<float> field(const render::GridGeometry& g, double t) {
  const std::vector<render::WaveFront> fronts{{g.centre(), 4 + 3 * t, 2.5, 1.0},
                                               {g.centre() + Vec3{4, -3, 2}, 3 + 2 * t, 2.0, -0.6}};
  return render::wave_field(g, fronts);
}

const char* kConfig = R"(
[output]
title = "halo test"
mode = "overwrite"
[image]
width = 40
height = 32
[rig]
spec = "fibonacci:4"
[schedule]
every_steps = 1
[video]
crf = 10
[render]
adaptive = false  # compared pixel for pixel with direct renders of each task alone (adaptive sampling refines where any task of the march does)
[[task]]
name = "hot"
type = "volume"
field = "a"
relative = false
window = [0.0, 0.8]
extinction_scale = 2.0
[[task]]
name = "iso"
type = "isosurface"
field = "a"
isovalues = [0.4]
[[task]]
name = "slice"
type = "slice"
field = "b"
axis = "x"
position = 0.45
relative = false
window = [-0.5, 1.0]
preset = "rainbow"
)";

// This rank's block for `layout`; stored ghost layers are clipped to the grid as a code's would be.
insitu::LocalBlock layout_block(const std::string& layout, const render::GridGeometry& g, int rank, int size) {
  int parts[3] = {1, 1, 1}, stored = 0, valid = -1;
  bool edges = false;
  insitu::LocalBlock b;
  if (layout == "1") {
    parts[0] = 1;
  } else if (layout == "2x2" || layout == "2x2full") {
    parts[0] = parts[1] = 2;
    stored = 3;
    valid = 2;
    edges = layout == "2x2full";
  } else if (layout == "2x1x2") {
    parts[0] = parts[2] = 2;
    stored = 2;
    valid = 1;
  } else if (layout == "3u") {
    stored = 2;
  } else {
    throw Error("unknown layout " + layout);
  }
  if (layout == "3u") {
    // Rank 0: a slab x < 10; ranks 1 and 2 split the rest unevenly in y.
    if (size != 3) throw Error("layout 3u needs 3 ranks");
    const int xs = 10, ys = 8;
    b.offset = {rank == 0 ? 0 : xs, rank == 2 ? ys : 0, 0};
    b.extent = {rank == 0 ? xs : g.dims[0] - xs, rank == 0 ? g.dims[1] : rank == 1 ? ys : g.dims[1] - ys, g.dims[2]};
  } else {
    if (parts[0] * parts[1] * parts[2] != size) throw Error("layout " + layout + " needs another rank count");
    const int idx[3] = {rank % parts[0], (rank / parts[0]) % parts[1], rank / (parts[0] * parts[1])};
    for (int a = 0; a < 3; ++a) {
      const int lo = g.dims[a] * idx[a] / parts[a], hi = g.dims[a] * (idx[a] + 1) / parts[a];
      b.offset[a] = lo;
      b.extent[a] = hi - lo;
    }
  }
  for (int a = 0; a < 3; ++a) {
    b.ghost_lo[a] = std::min(stored, b.offset[a]);
    b.ghost_hi[a] = std::min(stored, g.dims[a] - b.offset[a] - b.extent[a]);
    b.valid_lo[a] = valid < 0 ? -1 : std::min(valid, b.ghost_lo[a]);
    b.valid_hi[a] = valid < 0 ? -1 : std::min(valid, b.ghost_hi[a]);
  }
  b.edges_valid = edges;
  return b;
}

// The rank's arrays as a face-only (or, with edges_valid, full) halo exchange leaves them: true values
// in the owned box and the valid ghosts, garbage in every ghost the exchange does not fill.
template <class T>
std::vector<T> local_array(const std::vector<float>& whole, const render::GridGeometry& g, const insitu::LocalBlock& b) {
  std::vector<T> out;
  for (int k = b.offset[2] - b.ghost_lo[2]; k < b.offset[2] + b.extent[2] + b.ghost_hi[2]; ++k)
    for (int j = b.offset[1] - b.ghost_lo[1]; j < b.offset[1] + b.extent[1] + b.ghost_hi[1]; ++j)
      for (int i = b.offset[0] - b.ghost_lo[0]; i < b.offset[0] + b.extent[0] + b.ghost_hi[0]; ++i) {
        const int p[3] = {i, j, k};
        int outside = 0;
        bool valid = true;
        for (int a = 0; a < 3; ++a) {
          const int below = b.offset[a] - p[a], above = p[a] - (b.offset[a] + b.extent[a] - 1);
          const int vlo = b.valid_lo[a] < 0 ? b.ghost_lo[a] : b.valid_lo[a];
          const int vhi = b.valid_hi[a] < 0 ? b.ghost_hi[a] : b.valid_hi[a];
          if (below > 0) ++outside, valid = valid && below <= vlo;
          if (above > 0) ++outside, valid = valid && above <= vhi;
        }
        if (outside >= 2 && !b.edges_valid) out.push_back(T(1e30));  // edge / corner: never exchanged
        else if (!valid) out.push_back(std::numeric_limits<T>::quiet_NaN());  // stored, not kept up to date
        else out.push_back(T(whole[std::size_t((std::int64_t(k) * g.dims[1] + j) * g.dims[0] + i)]));
      }
  return out;
}

int write(const std::string& dir, const std::string& layout) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  insitu::SessionConfig cfg = insitu::parse_session_config_text(kConfig, "halo_mpi_test config");
  cfg.output_dir = dir;
  const render::GridGeometry g = test_grid();
  const insitu::LocalBlock blk = layout_block(layout, g, rank, size);
  insitu::Session session(cfg, g, blk, MPI_COMM_WORLD);
  const camera::Rig rig = camera::make_rig("fibonacci:4", camera::Domain{g.domain_lo(), g.domain_hi() - g.domain_lo()});
  int failures = 0, checked = 0, worst = 0;
  std::vector<float> whole_a, whole_b;
  std::vector<render::PartialImage> direct(1);
  session.set_frame_observer([&](int camera, int task, int, const Image& img) {
    const std::vector<render::PreparedField> fields{render::PreparedField(render::FieldView::whole(g, whole_a.data())),
                                                   render::PreparedField(render::FieldView::whole(g, whole_b.data()))};
    render::TaskSpec spec;
    if (task == 0)
      spec = render::TaskSpec::volume(0, render::TransferFunction::preset("hot", 2.0f), render::ValueWindow::absolute(0, 0.8));
    else if (task == 1)
      spec = render::TaskSpec::isosurface(0, 0.4f);
    else
      spec = render::TaskSpec::slice(1, 0, 0.45 * (g.dims[0] - 1) * g.spacing[0], render::TransferFunction::preset("rainbow"),
                                     render::ValueWindow::absolute(-0.5, 1));
    const camera::Camera cam = rig.camera(camera, 40, 32);
    render::render_brick(cam, fields, std::span<const render::TaskSpec>(&spec, 1), direct, cfg.render);  // the session's options (iso_antialias)
    const Image ref = render::finish_image(direct[0], cam, g);
    int maxdiff = 0;
    for (std::size_t i = 0; i < ref.pixels.size(); ++i)
      maxdiff = std::max(maxdiff, std::abs(int(ref.pixels[i]) - int(img.pixels[i])));
    ++checked;
    worst = std::max(worst, maxdiff);
    if (maxdiff > 1) {
      std::fprintf(stderr, "rank %d (%s): camera %d task %d differs from the whole-grid rendering by %d/255\n", rank,
                   layout.c_str(), camera, task, maxdiff);
      ++failures;
    }
  });
  const std::int64_t plane = std::int64_t(blk.extent[0] + blk.ghost_lo[0] + blk.ghost_hi[0]) *
                             (blk.extent[1] + blk.ghost_lo[1] + blk.ghost_hi[1]);
  const std::int64_t shift = blk.ghost_lo[0] + blk.ghost_lo[1] * std::int64_t(blk.extent[0] + blk.ghost_lo[0] + blk.ghost_hi[0]) +
                             blk.ghost_lo[2] * plane;
  for (int step = 0; step < 3; ++step) {
    const double t = 0.6 * step;
    whole_a = field(g, t);
    whole_b = field(g, t + 0.4);
    const std::vector<double> a = local_array<double>(whole_a, g, blk);
    const std::vector<float> b = local_array<float>(whole_b, g, blk);
    session.process(step, t, {{"a", a.data() + shift, insitu::ScalarType::f64, {0, 0, 0}},
                              {"b", b.data() + shift, insitu::ScalarType::f32, {0, 0, 0}}});
  }
  session.finalize();
  int all_fail = 0, all_checked = 0, all_worst = 0;
  MPI_Allreduce(&failures, &all_fail, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&checked, &all_checked, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&worst, &all_worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (rank == 0) {
    std::printf("%s on %d ranks: %d frames checked against the whole-grid rendering, largest difference %d/255, %d "
                "failures\n",
                layout.c_str(), size, all_checked, all_worst, all_fail);
    if (all_checked != 3 * 4 * 3) {
      std::fprintf(stderr, "expected %d frames checked, got %d\n", 3 * 4 * 3, all_checked);
      return 1;
    }
  }
  return all_fail == 0 ? 0 : 1;
}

int compare(const std::vector<std::string>& dirs) {
  const store::Database first = store::Database::open(dirs[0]);
  int rc = 0;
  for (std::size_t d = 1; d < dirs.size(); ++d) {
    const store::Database db = store::Database::open(dirs[d]);
    if (db.status() != store::Status::complete || db.frame_count() != first.frame_count() || db.frame_count() != 3) {
      std::fprintf(stderr, "%s: not complete or %d frames (first: %d, expected 3)\n", dirs[d].c_str(), db.frame_count(),
                   first.frame_count());
      return 1;
    }
    int maxdiff = 0, identical = 0, frames = 0;
    double worst = INFINITY;
    for (int c = 0; c < db.camera_count(); ++c)
      for (int t = 0; t < db.task_count(); ++t) {
        auto r0 = first.stream(c, t);
        auto r1 = db.stream(c, t);
        for (int f = 0; f < db.frame_count(); ++f) {
          const Image a = r0->read_rgba(f), b = r1->read_rgba(f);
          double se = 0;
          int md = 0;
          for (std::size_t i = 0; i < a.pixels.size(); ++i) {
            const int diff = std::abs(int(a.pixels[i]) - int(b.pixels[i]));
            md = std::max(md, diff);
            se += double(diff) * diff;
          }
          const double psnr = se == 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 * double(a.pixels.size()) / se);
          worst = std::min(worst, psnr);
          maxdiff = std::max(maxdiff, md);
          identical += md == 0;
          ++frames;
        }
      }
    std::printf("%s vs %s: %d of %d decoded frames identical, largest difference %d/255, worst PSNR %.1f dB\n",
                dirs[d].c_str(), dirs[0].c_str(), identical, frames, maxdiff, worst);
    if (worst < 45) rc = 1;
  }
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rc = 2;
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && argc == 4) rc = write(argv[2], argv[3]);
    else if (mode == "compare" && argc >= 4) rc = compare(std::vector<std::string>(argv + 2, argv + argc));
    else std::fprintf(stderr, "usage: halo_mpi_test write DIR LAYOUT | compare DIR1 DIR2...\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "halo_mpi_test: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
