#pragma once
// The in-situ benchmark's workload, shared by insitu_bench (one process, Google Benchmark) and
// insitu_mpi_bench (under mpirun): the seismic solver driven with in-situ visualization exactly as
// `panoptes run` does it (src/app/cmd_run.cpp: one TOML file split between the solver's and the
// session's parsers, φp and φs handed to Session::snapshot after compute_derived), from a config in
// examples/. To keep the benchmark short it runs `warmup_steps` steps without snapshots (the waves
// then fill the domain, as in the middle of the real run) and then `snapshots` snapshots at the
// file's cadence; every figure is per snapshot, so it applies to the whole run.
#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "insitu/session.hpp"
#include "seismic/config_toml.hpp"
#include "seismic/solver.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif
#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::bench {

/// One benchmark setting: a combined seismic + in-situ config file and what to override.
struct InsituSetting {
  std::string config;       ///< path of the TOML file (seismic and in-situ sections)
  std::string rig;          ///< overrides [rig] spec when not empty (fewer cameras, same geometry)
  int warmup_steps = 0;     ///< solver steps before the first snapshot (not timed per snapshot)
  int snapshots = 1;        ///< snapshots measured, at the file's every_steps cadence
  int gop = 0;              ///< overrides [video] gop when > 0
  int crf = -1;             ///< overrides [video] crf when >= 0
};

/// Per-snapshot costs (slowest rank per phase) and sizes of one run.
struct InsituResult {
  int ranks = 1, cores = 1, snapshots = 0, streams = 0, owned_streams_max = 0;
  int width = 0, height = 0;
  std::int64_t frames = 0;     ///< (camera, task) frames encoded, all ranks
  double simulation_s = 0;     ///< solver steps between snapshots + derived fields, per snapshot
  double copy_s = 0, render_s = 0, composite_s = 0, encode_s = 0, checkpoint_s = 0;  ///< per snapshot
  double wall_s = 0;           ///< wall time of the snapshot loop, per snapshot
  double db_bytes = 0, raw_bytes = 0;
  double rss_bytes_max = 0;    ///< largest resident set of a rank with everything open (last snapshot)
  double stream_bytes_max = 0; ///< per open stream: RSS growth from before the session to the last
                               ///< snapshot, less field and partial-image buffers, / owned streams
  double frames_per_core_s() const { return double(frames) / (wall_s * snapshots * cores); }
};

inline std::int64_t resident_bytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return std::int64_t(resident) * ::sysconf(_SC_PAGESIZE);
}

inline std::int64_t directory_bytes(const std::filesystem::path& d) {
  std::int64_t n = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(d))
    if (e.is_regular_file()) n += std::int64_t(e.file_size());
  return n;
}

/// Runs one setting (collective when `comm_world` is true: every rank of MPI_COMM_WORLD calls it).
inline InsituResult run_insitu_setting(const InsituSetting& s, const std::string& out_dir, bool comm_world = false) {
  std::ifstream in(s.config);
  if (!in) throw FileError(s.config, "cannot open the benchmark configuration");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::vector<std::string> seismic_sections{"grid",   "time",     "medium",   "boundary",
                                                  "attenuation", "source", "receiver", "receiver_line"};
  std::string seis_text;
  insitu::SessionConfig cfg = insitu::parse_combined_config(ss.str(), s.config, seismic_sections, seis_text);
  const seismic::RunConfig rc =
      seismic::parse_run_config(seis_text, s.config, std::filesystem::path(s.config).parent_path().string());
  if (!s.rig.empty()) cfg.rig = s.rig;
  if (s.gop > 0) cfg.video.gop = s.gop;
  if (s.crf >= 0) cfg.video.crf = s.crf;
  cfg.output_dir = out_dir;
  cfg.mode = insitu::OutputMode::overwrite;
  cfg.up = {0, 0, -1};  // as panoptes run: depth is +z
  cfg.validate();

  InsituResult r;
#ifdef PANOPTES_HAVE_MPI
  std::unique_ptr<seismic::Solver> solver = comm_world ? std::make_unique<seismic::Solver>(rc.solver, MPI_COMM_WORLD)
                                                       : std::make_unique<seismic::Solver>(rc.solver);
#else
  (void)comm_world;
  auto solver = std::make_unique<seismic::Solver>(rc.solver);
#endif
  const auto& g = rc.solver.grid;
  const render::GridGeometry grid{{g.nx, g.ny, g.nz}, {0, 0, 0}, {g.h, g.h, g.h}};
  insitu::LocalBlock block;
  block.offset = {0, 0, solver->k_begin()};
  block.extent = {g.nx, g.ny, solver->k_end() - solver->k_begin()};
  solver->run(s.warmup_steps);

  ::malloc_trim(0);
  const std::int64_t rss0 = resident_bytes();
#ifdef PANOPTES_HAVE_MPI
  std::unique_ptr<insitu::Session> session =
      comm_world ? std::make_unique<insitu::Session>(cfg, grid, block, MPI_COMM_WORLD)
                 : std::make_unique<insitu::Session>(cfg, grid, block);
#else
  auto session = std::make_unique<insitu::Session>(cfg, grid, block);
#endif
  auto input = [](const char* name, const seismic::FieldView& v) {
    return insitu::FieldInput{name, v.data, insitu::ScalarType::f32,
                              {1, std::int64_t(v.stride_y), std::int64_t(v.stride_z)}};
  };
  using Clock = std::chrono::steady_clock;
  double sim = 0;
  const auto t0 = Clock::now();
  for (int n = 0; n < s.snapshots; ++n) {
    const auto ts = Clock::now();
    for (std::int64_t k = 0; k < cfg.schedule.every_steps; ++k) solver->step();
    solver->compute_derived();
    sim += std::chrono::duration<double>(Clock::now() - ts).count();
    session->snapshot(solver->velocity_time(), {input("phi_p", solver->phi_p()), input("phi_s", solver->phi_s())});
  }
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  const insitu::SessionStats mine = session->stats();
  const std::int64_t rss1 = resident_bytes();
  const int owned_streams = mine.owned_cameras * session->task_count();
  double stream_bytes =
      owned_streams > 0
          ? double(rss1 - rss0 - mine.field_buffer_bytes - mine.partial_buffer_bytes) / owned_streams
          : 0.0;
  double rss = double(rss1);
  r.streams = session->camera_count() * session->task_count();
  r.owned_streams_max = owned_streams;
  const insitu::SessionStats st = session->reduced_stats();
  session->finalize();
  r.ranks = session->ranks();
#ifdef PANOPTES_HAVE_MPI
  if (comm_world) {
    MPI_Allreduce(MPI_IN_PLACE, &sim, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &stream_bytes, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &rss, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &r.owned_streams_max, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  }
#endif
  session.reset();
  const double n = double(st.snapshots);
  r.snapshots = st.snapshots;
  r.frames = st.frames_encoded;
  r.simulation_s = sim / n;
  r.copy_s = st.time.copy / n;
  r.render_s = st.time.render / n;
  r.composite_s = st.time.composite / n;
  r.encode_s = st.time.encode / n;
  r.checkpoint_s = st.time.checkpoint / n;
  r.wall_s = wall / n;
  int threads = 1;
#ifdef _OPENMP
  threads = omp_get_max_threads();
#endif
  r.cores = std::min(int(std::max(1u, std::thread::hardware_concurrency())), r.ranks * threads);
  r.width = cfg.width;
  r.height = cfg.height;
  r.raw_bytes = n * 2.0 * double(g.nx) * g.ny * g.nz * 4.0;
  if (!comm_world || solver->rank() == 0) r.db_bytes = double(directory_bytes(out_dir));
  r.rss_bytes_max = rss;
  r.stream_bytes_max = stream_bytes;
  return r;
}

}  // namespace panoptes::bench
