// MPI test of the grid stage (issue 33), run by ctest under mpiexec with 1, 2 and 4 ranks for each
// non-uniform grid kind.
//   insitu_grid_mpi_test write DIR KIND — the analytic shell field (grid/sample.hpp) on a KIND grid
//       (rectilinear, spherical, yinyang), split among the ranks (each block with a stored ghost layer
//       full of 1e30 that must never be read), handed to a GridAdapter + Session for 3 snapshots.
//       Every finished frame is saved raw (DIR/frames/) and checked on its owner rank against the
//       same field sampled directly on the session's uniform grid and rendered whole (PSNR ≥ 40 dB).
//   insitu_grid_mpi_test compare DIR1 DIR2... — the saved frames of every run equal the first run's
//       (reports whether bitwise; fails below 45 dB).
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "grid/sample.hpp"
#include "insitu/grid_adapter.hpp"
#include "insitu/session.hpp"
#include "render/renderer.hpp"

using namespace panoptes;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = std::numbers::pi;

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(a + (b - a) * i / (n - 1));
  return v;
}

grid::GridDescription source_grid(const std::string& kind) {
  if (kind == "rectilinear") {
    std::vector<double> x;
    for (int i = 0; i < 30; ++i) x.push_back(std::tanh(1.2 * (-1 + 2.0 * i / 29)) / std::tanh(1.2));
    return grid::GridDescription::rectilinear(x, linspace(-1, 1, 26), x);
  }
  if (kind == "spherical") {
    std::vector<double> t, p;
    for (int j = 0; j < 32; ++j) t.push_back((j + 0.5) * kPi / 32);
    for (int k = 0; k < 64; ++k) p.push_back(k * 2 * kPi / 64);
    return grid::GridDescription::spherical(linspace(0.35, 1, 14), t, p);
  }
  if (kind == "yinyang") return grid::GridDescription::yinyang_standard(linspace(0.35, 1, 14), 20, 54);
  throw Error("kind " + kind + "; expected rectilinear, spherical or yinyang");
}

// This rank's blocks: rectilinear split along x (every rank's slab of the uniform grid then reads
// from every rank), spherical along φ, Yin-Yang: one patch per rank (even ranks Yin, odd Yang)
// split along θ; a single rank holds both patches.
std::vector<insitu::GridBlock> blocks_of(const grid::GridDescription& g, const std::string& kind, int rank, int size) {
  const render::Index3 n = g.dims();
  auto split = [&](int patch, int axis, int parts, int index) {
    insitu::GridBlock b;
    b.patch = patch;
    b.extent = n;
    const int lo = n[axis] * index / parts, hi = n[axis] * (index + 1) / parts;
    b.offset[axis] = lo;
    b.extent[axis] = hi - lo;
    b.ghost_lo = {1, 1, 1};  // stored but never read: filled with 1e30
    b.ghost_hi = {1, 1, 1};
    return b;
  };
  if (kind == "rectilinear") return {split(0, 0, size, rank)};
  if (kind == "spherical") return {split(0, 2, size, rank)};
  if (size == 1) return {split(0, 1, 1, 0), split(1, 1, 1, 0)};
  const int patch = rank % 2, mates = (size - patch + 1) / 2;
  return {split(patch, 1, mates, rank / 2)};
}

// The field on a block's ghosted box as doubles (x fastest), ghosts 1e30.
std::vector<double> block_data(const grid::GridDescription& g, const insitu::GridBlock& b, const grid::ShellField& f) {
  const render::Index3 e{b.extent[0] + b.ghost_lo[0] + b.ghost_hi[0], b.extent[1] + b.ghost_lo[1] + b.ghost_hi[1],
                         b.extent[2] + b.ghost_lo[2] + b.ghost_hi[2]};
  std::vector<double> v(std::size_t(e[0]) * std::size_t(e[1]) * std::size_t(e[2]), 1e30);
  for (int k = 0; k < b.extent[2]; ++k)
    for (int j = 0; j < b.extent[1]; ++j)
      for (int i = 0; i < b.extent[0]; ++i)
        v[(std::size_t(k + b.ghost_lo[2]) * std::size_t(e[1]) + std::size_t(j + b.ghost_lo[1])) * std::size_t(e[0]) +
          std::size_t(i + b.ghost_lo[0])] = f(g.point(b.patch, b.offset[0] + i, b.offset[1] + j, b.offset[2] + k));
  return v;
}

const char* kConfig = R"(
[output]
title = "grid stage mpi test"
overwrite = true
[image]
width = 64
height = 64
[rig]
spec = "fibonacci:4"
[schedule]
every_steps = 1
[video]
crf = 10
[render]
adaptive = false  # compared pixel for pixel with direct renders of each task alone (adaptive sampling refines where any task of the march does)
[[task]]
name = "shell"
type = "volume"
field = "T"
preset = "p-wave"
relative = false
window = [0.0, 1.2]
extinction_scale = 4.0
[[task]]
name = "equator"
type = "slice"
field = "T"
axis = "z"
position = 0.55
relative = false
window = [-1.2, 1.2]
preset = "diverging"
)";

int write(const std::string& dir, const std::string& kind) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  insitu::SessionConfig cfg = insitu::parse_session_config_text(kConfig, "grid_mpi_test config");
  cfg.output_dir = dir;
  const grid::GridDescription g = source_grid(kind);
  const std::vector<insitu::GridBlock> mine = blocks_of(g, kind, rank, size);
  insitu::GridAdapter adapter(g, mine, {48, 0.0f}, MPI_COMM_WORLD);
  insitu::Session session(cfg, adapter.render_grid(), adapter.render_block(), MPI_COMM_WORLD);
  const render::GridGeometry rg = adapter.render_grid();
  if (rank == 0) fs::create_directories(dir + "/frames");
  MPI_Barrier(MPI_COMM_WORLD);
  grid::ShellField field;
  int failures = 0, checked = 0;
  double worst = INFINITY;
  session.set_frame_observer([&](int camera, int task, int frame, const Image& img) {
    std::ofstream(dir + "/frames/c" + std::to_string(camera) + "_t" + std::to_string(task) + "_f" +
                      std::to_string(frame) + ".rgba",
                  std::ios::binary)
        .write(reinterpret_cast<const char*>(img.pixels.data()), std::streamsize(img.pixels.size()));
    // The same field sampled directly on the uniform grid, rendered whole.
    const std::vector<float> direct = grid::sample(rg, field);
    const render::TaskSpec spec =
        task == 0 ? render::TaskSpec::volume(0, render::TransferFunction::preset("p-wave", 4.0f),
                                             render::ValueWindow::absolute(0, 1.2))
                  : render::TaskSpec::slice(0, 2, rg.origin.z + 0.55 * (rg.dims[2] - 1) * rg.spacing.z,
                                            render::TransferFunction::preset("diverging"),
                                            render::ValueWindow::absolute(-1.2, 1.2));
    const std::vector<render::PreparedField> fields{render::PreparedField(render::FieldView::whole(rg, direct.data()))};
    std::vector<render::PartialImage> part(1);
    const camera::Camera cam = camera::make_rig("fibonacci:4", camera::Domain{rg.domain_lo(), rg.domain_hi() - rg.domain_lo()})
                                   .camera(camera, 64, 64);
    render::render_brick(cam, fields, std::span<const render::TaskSpec>(&spec, 1), part);
    const double db = psnr(render::finish_image(part[0], cam, rg), img);
    worst = std::min(worst, db);
    ++checked;
    if (db < 40) {
      std::fprintf(stderr, "rank %d: camera %d task %d frame %d: %.1f dB from the directly sampled field\n", rank,
                   camera, task, frame, db);
      ++failures;
    }
  });
  for (int step = 0; step < 3; ++step) {
    field.t = 0.8 * step;
    std::vector<std::vector<double>> data;
    std::vector<insitu::FieldInput> inputs;
    for (const insitu::GridBlock& b : mine) data.push_back(block_data(g, b, field));
    for (std::size_t b = 0; b < mine.size(); ++b) {
      const render::Index3 e{mine[b].extent[0] + 2, mine[b].extent[1] + 2, mine[b].extent[2] + 2};
      const std::int64_t first = (std::int64_t(e[1]) + 1) * e[0] + 1;  // the first owned point: (1, 1, 1)
      inputs.push_back({"T", data[b].data() + first, insitu::ScalarType::f64, {0, 0, 0}});
    }
    session.process(step, field.t, adapter.adapt(inputs));
  }
  session.finalize();
  double all_worst = 0;
  int total_fail = 0, total_checked = 0;
  MPI_Allreduce(&worst, &all_worst, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&failures, &total_fail, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&checked, &total_checked, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0)
    std::printf("%s on %d ranks: %s, uniform cover %dx%dx%d; %d frames, worst %.1f dB from the directly sampled "
                "field; adapter %.3f s on rank 0\n",
                kind.c_str(), size, g.summary().c_str(), rg.dims[0], rg.dims[1], rg.dims[2], total_checked, all_worst,
                adapter.seconds());
  if (rank == 0 && total_checked != 3 * 4 * 2) {
    std::fprintf(stderr, "expected %d frames, got %d\n", 3 * 4 * 2, total_checked);
    return 1;
  }
  return total_fail == 0 ? 0 : 1;
}

int compare(const std::vector<std::string>& dirs) {
  double worst = INFINITY;
  int files = 0, identical = 0;
  for (const auto& e : fs::directory_iterator(dirs[0] + "/frames")) {
    auto read = [](const fs::path& p) {
      std::ifstream in(p, std::ios::binary);
      return std::vector<char>(std::istreambuf_iterator<char>(in), {});
    };
    const std::vector<char> a = read(e.path());
    for (std::size_t d = 1; d < dirs.size(); ++d) {
      const std::vector<char> b = read(fs::path(dirs[d]) / "frames" / e.path().filename());
      ++files;
      if (a.size() != b.size() || a.empty()) {
        std::fprintf(stderr, "%s: missing or of another size in %s\n", e.path().filename().c_str(), dirs[d].c_str());
        return 1;
      }
      if (a == b) {
        ++identical;
        continue;
      }
      double se = 0;
      std::size_t n = 0;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (i % 4 == 3) continue;
        const double x = double(std::uint8_t(a[i])) - double(std::uint8_t(b[i]));
        se += x * x;
        ++n;
      }
      worst = std::min(worst, 10 * std::log10(255.0 * 255.0 / (se / double(n))));
    }
  }
  std::printf("%d frame comparisons, %d bitwise identical; worst PSNR of the others %.1f dB\n", files, identical,
              worst);
  return files > 0 && worst >= 45 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rc = 2;
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && argc == 4) rc = write(argv[2], argv[3]);
    else if (mode == "compare" && argc >= 4) rc = compare(std::vector<std::string>(argv + 2, argv + argc));
    else std::fprintf(stderr, "usage: insitu_grid_mpi_test write DIR KIND | compare DIR1 DIR2...\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "insitu_grid_mpi_test: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
