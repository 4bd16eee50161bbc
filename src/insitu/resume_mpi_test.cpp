// MPI test of [output] mode = "resume" (issue 28): a run on 2 ranks abandoned after 3 snapshots (the
// session destroyed without finalize, as when a job is stopped) and restarted from step 2 on 3 ranks
// (so every camera changes owner and its new owner continues the movie) equals the uninterrupted
// 2-rank run in every decoded frame of every movie and every time.
//   resume_mpi_test write DIR FIRST END create|resume [abandon]  — steps FIRST..END-1
//   resume_mpi_test compare DIR1 DIR2
#include <mpi.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "insitu/session.hpp"
#include "render/synthetic_fields.hpp"
#include "store/database.hpp"

using namespace panoptes;

namespace {

const char* kConfig = R"(
[image]
width = 36
height = 30
[rig]
spec = "fibonacci:5"
[schedule]
every_steps = 1
[[task]]
name = "v"
field = "a"
[[task]]
name = "iso"
type = "isosurface"
field = "a"
isovalues = [0.3]
relative = true
)";

render::GridGeometry test_grid() { return {{22, 20, 18}, {0, 0, 0}, {1, 1, 1}}; }
double time_of(int step) { return 0.25 * step; }

int write(const std::string& dir, int first, int end, const std::string& mode, bool abandon) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  insitu::SessionConfig cfg = insitu::parse_session_config_text(kConfig, "resume_mpi_test config");
  cfg.output_dir = dir;
  cfg.mode = insitu::parse_output_mode(mode);
  const render::GridGeometry g = test_grid();
  const insitu::LocalBlock blk = insitu::LocalBlock::slab(g, 2, size, rank, 2);
  auto session = std::make_unique<insitu::Session>(cfg, g, blk, MPI_COMM_WORLD);
  const std::int64_t plane = std::int64_t(g.dims[0]) * g.dims[1];
  int taken = 0;
  for (int step = first; step < end; ++step) {
    const std::vector<render::WaveFront> fronts{{g.centre(), 3 + 2 * time_of(step), 2.0, 1.0}};
    const std::vector<float> whole = render::wave_field(g, fronts);
    const float* own = whole.data() + std::int64_t(blk.offset[2]) * plane;
    taken += session->process(step, time_of(step), {{"a", own, insitu::ScalarType::f32, {1, g.dims[0], plane}}});
  }
  if (!abandon) session->finalize();
  const int snapshots = session->snapshots();
  session.reset();  // abandoned: the database is left interrupted with its last checkpoint
  if (rank == 0) std::printf("%s: %d ranks, steps %d..%d, %d snapshots taken, %d in the database\n", dir.c_str(), size,
                             first, end - 1, taken, snapshots);
  return 0;
}

int compare(const std::string& a_dir, const std::string& b_dir) {
  const store::Database a = store::Database::open(a_dir), b = store::Database::open(b_dir);
  if (b.status() != store::Status::complete || b.frame_count() != a.frame_count() || a.frame_count() != 6 ||
      a.manifest().times != b.manifest().times) {
    std::fprintf(stderr, "%s: status %s, %d frames, times differ: %d; expected complete, %d frames as %s\n", b_dir.c_str(),
                 std::string(store::to_string(b.status())).c_str(), b.frame_count(),
                 int(a.manifest().times != b.manifest().times), a.frame_count(), a_dir.c_str());
    return 1;
  }
  int frames = 0;
  for (int c = 0; c < a.camera_count(); ++c)
    for (int t = 0; t < a.task_count(); ++t) {
      auto ra = a.stream(c, t), rb = b.stream(c, t);
      if (rb->frame_count() != a.frame_count()) {
        std::fprintf(stderr, "camera %d task %d: %d frames in the movie\n", c, t, rb->frame_count());
        return 1;
      }
      for (int f = 0; f < a.frame_count(); ++f, ++frames)
        if (ra->read_rgba(f).pixels != rb->read_rgba(f).pixels) {
          std::fprintf(stderr, "camera %d task %d frame %d differs\n", c, t, f);
          return 1;
        }
    }
  std::printf("%s equals %s: %d decoded frames identical, times identical\n", b_dir.c_str(), a_dir.c_str(), frames);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rc = 2;
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && (argc == 6 || argc == 7))
      rc = write(argv[2], std::stoi(argv[3]), std::stoi(argv[4]), argv[5], argc == 7 && std::string(argv[6]) == "abandon");
    else if (mode == "compare" && argc == 4)
      rc = compare(argv[2], argv[3]);
    else
      std::fprintf(stderr, "usage: resume_mpi_test write DIR FIRST END create|resume [abandon] | compare DIR1 DIR2\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "resume_mpi_test: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
