// `panoptes run CONFIG.toml`: the seismic solver with in-situ visualization from one TOML file
// (works under mpirun -np N). The seismic sections ([grid], [time], [medium], [boundary],
// [attenuation], [[source]], [[receiver]], [receiver_line]) go to the solver's own parser; the
// in-situ sections ([output], [image], [rig], [schedule], [video], [render], [[task]]) to
// insitu::parse_session_config. Everything is checked before the first step.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>

#include "app/command.hpp"
#include "app/mpi_scope.hpp"
#include "app/seismic_run.hpp"
#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/file_read.hpp"
#include "core/memory.hpp"
#include "insitu/resources.hpp"
#include "seismic/resources.hpp"
#include "insitu/session.hpp"
#include "seismic/config_toml.hpp"
#include "seismic/solver.hpp"
#include "store/database.hpp"

#include <omp.h>

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::app {

namespace {

const std::set<std::string> kSeismicSections{"grid",   "time",     "medium",       "boundary",
                                             "attenuation", "source", "receiver", "receiver_line"};

std::int64_t directory_bytes(const std::filesystem::path& dir) {
  std::int64_t n = 0;
  std::error_code ec;
  for (auto it = std::filesystem::recursive_directory_iterator(dir, ec); it != std::filesystem::recursive_directory_iterator();
       it.increment(ec))
    if (it->is_regular_file(ec)) n += std::int64_t(it->file_size(ec));
  return n;
}

std::string human_bytes(double b) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB"};
  int u = 0;
  while (b >= 1000 && u < 4) b /= 1000, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", b, units[u]);
  return buf;
}

insitu::FieldInput input_of(const char* name, const seismic::FieldView& v) {
  return {name, v.data, insitu::ScalarType::f32, {1, std::int64_t(v.stride_y), std::int64_t(v.stride_z)}};
}

// The solver's and the session's memory on this rank, checked together before either exists; and
// the movies every rank will hold open. Collective: every rank refuses, or none.
void check_run_resources(const seismic::SolverConfig& solver, const insitu::SessionConfig& cfg, bool force) {
  int ranks = 1, rank = 0, sharing = 1;
#ifdef PANOPTES_HAVE_MPI
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &sharing);
  MPI_Comm_free(&node);
#endif
  std::string refusal;
  try {
    const auto& g = solver.grid;
    const render::GridGeometry grid{{g.nx, g.ny, g.nz}, {0, 0, 0}, {g.h, g.h, g.h}};
    const long long cameras = insitu::rig_camera_count(cfg, grid);
    std::int64_t tasks = 0;
    for (const auto& t : cfg.tasks)
      tasks += std::int64_t(std::max<std::size_t>(
          1, std::max({t.isovalues.size(), t.slice_positions.size(), t.windows.size()})));
    insitu::check_open_streams(cameras, int(std::min<std::int64_t>(tasks, INT_MAX)), ranks,
                               insitu::packed_layout(cfg, cameras * std::min<std::int64_t>(tasks, INT_MAX)));
    if (!force) {
      MemoryEstimate e = seismic::estimate_solver_memory(solver, ranks);
      const double slab = double(g.nx) * g.ny * (std::ceil(double(g.nz) / ranks) + 4);
      e.add(insitu::estimate_session_memory(cfg, slab, cameras, ranks, omp_get_max_threads()));
      refusal = memory_refusal(e, available_memory(), sharing, "this run", "pass --force");
    }
  } catch (const std::exception& e) {
    refusal = e.what();
  }
  int refused = refusal.empty() ? 0 : 1;
#ifdef PANOPTES_HAVE_MPI
  MPI_Allreduce(MPI_IN_PLACE, &refused, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
#endif
  if (refused) throw Error(refusal.empty() ? "another rank of this run refused to start (see its message)" : refusal);
}

}  // namespace

void run_seismic_insitu(const std::string& text, const std::string& source, const std::string& base_dir,
                        const SeismicRunOptions& options) {
  // Split the file: seismic sections to the solver's parser, the rest to the session's.
  const std::vector<std::string> seismic_sections(kSeismicSections.begin(), kSeismicSections.end());
  std::string seis_text;
  insitu::SessionConfig cfg = insitu::parse_combined_config(text, source, seismic_sections, seis_text);
  const seismic::RunConfig rc = seismic::parse_run_config(seis_text, source, base_dir);
  rc.solver.validate();
  if (rc.solver.steps <= 0)
    throw FileError(source, "[time] steps = " + std::to_string(rc.solver.steps) +
                                ": a run needs at least one step (a database without frames would be written)");
  if (!options.out.empty()) cfg.output_dir = options.out;
  if (options.overwrite && options.resume) throw Error("--overwrite and --resume exclude each other");
  if (options.overwrite) cfg.mode = insitu::OutputMode::overwrite;
  if (options.overwrite) cfg.keep_interrupted = false;  // asked for on the command line: replace it
  if (options.resume) cfg.mode = insitu::OutputMode::resume;
  cfg.validate();
  cfg.program = "panoptes run";
  cfg.existing_database_advice = !options.existing_database_advice.empty()
                                     ? options.existing_database_advice
                                     : "add --overwrite (or [output] mode = \"overwrite\") to replace it, or --resume "
                                       "(mode = \"resume\") to continue it after a restart";
  cfg.command_line = options.command_line;
  cfg.units = "m";
  // The solver works in SI: times in s, velocities in m/s, so phi_p = div v and phi_s = |curl v| are in 1/s.
  if (cfg.time_units.empty()) cfg.time_units = "s";
  for (const char* f : {"phi_p", "phi_s"}) cfg.field_units.try_emplace(f, "1/s");
  // Depth is +z (down): the sky is −z, so the rig's poles, latitudes and the images' up follow it
  // (the free surface at the top of every image) unless the file says otherwise.
  if (cfg.up_axis.empty()) cfg.up_axis = "z_down";
  for (const auto& t : cfg.tasks)
    for (const auto& f : t.fields)
      if (f != "phi_p" && f != "phi_s")
        throw FileError(source, "task \"" + t.name + "\": field \"" + f +
                                    "\"; the seismic run provides phi_p (div v) and phi_s (|curl v|)");

  MpiScope mpi;
  check_run_resources(rc.solver, cfg, options.force);
  cfg.check_memory = false;  // checked above for the solver and the session together
#ifdef PANOPTES_HAVE_MPI
  seismic::Solver solver(rc.solver, MPI_COMM_WORLD);
#else
  seismic::Solver solver(rc.solver);
#endif
  const int steps = rc.solver.steps;
  // A snapshot interval below the time step cannot be honoured (at most one snapshot per step).
  if (cfg.schedule.every_time > 0 && cfg.schedule.every_time < solver.dt())
    throw FileError(source, "schedule.every_time = " + std::to_string(cfg.schedule.every_time) +
                                " s is shorter than the solver's time step of " + std::to_string(solver.dt()) +
                                " s; expected at least one step between snapshots");
  // Expected number of snapshots, for the progress bar (the times of velocity are (s + 0.5)·dt).
  const std::int64_t expected64 =
      cfg.schedule.every_steps > 0
          ? steps / cfg.schedule.every_steps
          : std::int64_t(std::floor((steps - 0.5) * solver.dt() / cfg.schedule.every_time)) + 1 -
                std::int64_t(std::floor(-0.5 * solver.dt() / cfg.schedule.every_time) + 1);
  int expected = int(std::min<std::int64_t>(expected64, INT_MAX));
  if (cfg.schedule.max_snapshots > 0) expected = std::min(expected, cfg.schedule.max_snapshots);
  if (expected <= 0)
    throw FileError(source, "the schedule takes no snapshot in " + std::to_string(steps) + " steps of " +
                                std::to_string(solver.dt()) + " s (schedule." +
                                (cfg.schedule.every_steps > 0 ? "every_steps = " + std::to_string(cfg.schedule.every_steps)
                                                              : "every_time = " + std::to_string(cfg.schedule.every_time)) +
                                "); the database would hold no frames");
  const auto& g = rc.solver.grid;
  const render::GridGeometry grid{{g.nx, g.ny, g.nz}, {0, 0, 0}, {g.h, g.h, g.h}};
  insitu::LocalBlock block;
  block.offset = {0, 0, solver.k_begin()};
  block.extent = {g.nx, g.ny, solver.k_end() - solver.k_begin()};
#ifdef PANOPTES_HAVE_MPI
  insitu::Session session(cfg, grid, block, MPI_COMM_WORLD);
#else
  insitu::Session session(cfg, grid, block);
#endif
  const bool root = solver.rank() == 0;
  const bool tty = ::isatty(STDERR_FILENO);
  // A replaced database's seismograms are the old run's: they go with it (issue 42: a receiver the new
  // run no longer has kept its old CSV beside the new movies). Only the .csv files this command writes.
  if (root && cfg.mode != insitu::OutputMode::resume) {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(cfg.output_dir + "/seismograms", ec))
      if (e.path().extension() == ".csv" && e.is_regular_file()) std::filesystem::remove(e.path(), ec);
  }
  if (root && !options.quiet)
    std::fprintf(stderr,
                 "panoptes run: %dx%dx%d grid, %d steps of %.3g s on %d rank(s); %d cameras x %d tasks = %d streams of "
                 "%dx%d, ~%d snapshots -> %s\n",
                 g.nx, g.ny, g.nz, steps, solver.dt(), solver.ranks(), session.camera_count(), session.task_count(),
                 session.camera_count() * session.task_count(), cfg.width, cfg.height, expected,
                 cfg.output_dir.c_str());
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  double sim = 0;
  install_stop_handlers();
  int stop_signal = 0;
  for (int s = 0; s < steps; ++s) {
    // SIGINT/SIGTERM: every rank must leave at the same step (the solver and the session are
    // collective), so the request is agreed on once per step (an 8-byte allreduce).
    stop_signal = stop_requested();
#ifdef PANOPTES_HAVE_MPI
    if (solver.ranks() > 1) MPI_Allreduce(MPI_IN_PLACE, &stop_signal, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
#endif
    if (stop_signal) break;
    auto ts = Clock::now();
    solver.step();
    sim += std::chrono::duration<double>(Clock::now() - ts).count();
    // Snapshot after steps N, 2N, ... (step s + 1 counted from 1, so the first one shows waves).
    if (!session.due(s + 1, solver.velocity_time())) continue;
    ts = Clock::now();
    solver.compute_derived();
    sim += std::chrono::duration<double>(Clock::now() - ts).count();
    session.snapshot(solver.velocity_time(), {input_of("phi_p", solver.phi_p()), input_of("phi_s", solver.phi_s())});
    if (root && !options.quiet) {
      const insitu::SessionStats st = session.stats();
      const double el = std::chrono::duration<double>(Clock::now() - t0).count();
      const double eta = el * double(steps - s - 1) / double(s + 1);
      std::fprintf(stderr,
                   "%ssnapshot %d/%d  step %d/%d  %.0f s elapsed, ETA %.0f s | simulation %.1f s, render %.1f s, "
                   "composite %.1f s, encode %.1f s%s",
                   tty ? "\r" : "", st.snapshots, expected, s + 1, steps, el, eta, sim, st.time.render + st.time.copy,
                   st.time.composite, st.time.encode, tty ? "  " : "\n");
    }
  }
  // [[receiver]] / [receiver_line] (issue 42: accepted and then ignored before): their seismograms, as
  // `panoptes seismic` writes them, in the database's own seismograms/ folder; also when stopped early
  // (what was recorded so far). Collective: rank 0 gathers every trace.
  const std::size_t receivers = rc.solver.receivers.size();
  if (receivers > 0) {
    const std::string dir = cfg.output_dir + "/seismograms";
    solver.write_seismograms(dir);
    if (root)
      std::printf("seismograms: %zu receiver%s -> %s/<name>.csv (time,vx,vy,vz)\n", receivers, receivers == 1 ? "" : "s",
                  dir.c_str());
  }
  if (stop_signal) {
    // The session's destructor flushes every movie and marks the database interrupted (removing the
    // lock); every snapshot taken so far was checkpointed and stays readable.
    if (root && tty && !options.quiet) std::fprintf(stderr, "\n");
    throw Interrupted(stop_signal, cfg.output_dir + ": stopped by " + signal_name(stop_signal) + " after " +
                                       std::to_string(session.snapshots()) +
                                       " snapshot(s); the database is marked interrupted and every snapshot taken is readable");
  }
  session.finalize();
  const insitu::SessionStats st = session.reduced_stats();
  const std::vector<insitu::RankOverhead> overhead = session.overhead();
#ifdef PANOPTES_HAVE_MPI
  MPI_Allreduce(MPI_IN_PLACE, &sim, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
#endif
  if (root) {
    if (tty && !options.quiet) std::fprintf(stderr, "\n");
    const double el = std::chrono::duration<double>(Clock::now() - t0).count();
    const std::int64_t db_bytes = directory_bytes(cfg.output_dir);
    const double raw = double(st.snapshots) * 2.0 * double(g.nx) * g.ny * g.nz * 4.0;
    const double frames = double(st.frames_encoded);
    std::printf("wrote %s: %d cameras x %d tasks = %d streams, %d frames each (%.0f camera-frames) of %dx%d\n",
                cfg.output_dir.c_str(), session.camera_count(), session.task_count(),
                session.camera_count() * session.task_count(), st.snapshots, frames, cfg.width, cfg.height);
    std::printf("database %s; the raw fields (phi_p, phi_s as float32, %d snapshots) would take %s (movies = %.1f %%)\n",
                human_bytes(double(db_bytes)).c_str(), st.snapshots, human_bytes(raw).c_str(),
                raw > 0 ? 100.0 * double(db_bytes) / raw : 0.0);
    std::printf("time %.1f s on %d rank(s): simulation %.1f s, render %.1f s, composite %.1f s, encode %.1f s, "
                "checkpoint %.1f s (slowest rank per phase); %.1f camera-frames/s; peak memory per rank %s\n",
                el, solver.ranks(), sim, st.time.render + st.time.copy, st.time.composite, st.time.encode,
                st.time.checkpoint, el > 0 ? frames / el : 0.0, human_bytes(double(st.peak_rss_bytes)).c_str());
    std::fputs(insitu::overhead_report(overhead).c_str(), stdout);
    if (!options.overhead_note.empty()) std::printf("%s\n", options.overhead_note.c_str());
    std::printf("open it with: panoptes play %s\n", cfg.output_dir.c_str());
  }
}

namespace cmd_run {  // named, not anonymous: the unity build joins the command units

CommandRegistration reg([](CLI::App& root) {
  auto config = std::make_shared<std::string>();
  auto opt = std::make_shared<SeismicRunOptions>();
  auto* sub = root.add_subcommand(
      "run",
      "Run the seismic solver with in-situ visualization from one TOML file: every camera of a rig x every "
      "task becomes a movie in a database (works under mpirun -np N). Keys of the solver sections are those "
      "of `panoptes seismic --help`; in-situ keys are listed below. Fields for tasks: phi_p (div v), "
      "phi_s (|curl v|).");
  sub->add_option("CONFIG", *config, "TOML configuration file")->required();
  sub->add_option("--out", opt->out, "Database directory (overrides [output] dir)");
  sub->add_flag("--overwrite", opt->overwrite, "Replace an existing database ([output] mode = \"overwrite\")");
  sub->add_flag("--resume", opt->resume,
                "Continue the interrupted database after a restart: its snapshots stay, the run's snapshots at or "
                "before its last time are skipped, the movies go on ([output] mode = \"resume\"; a complete "
                "database is refused unless [output] resume_complete = true)");
  sub->add_flag("-q,--quiet", opt->quiet, "No progress output");
  sub->add_flag("--force", opt->force,
                "Start even when the estimated memory per rank exceeds what the rank has available");
  sub->footer(std::string(insitu::config_keys_help()));
  sub->callback([config, opt] {
    const std::string text = read_regular_file(*config, insitu::kMaxConfigBytes, "configuration file");
    opt->command_line = "panoptes run " + *config + (opt->out.empty() ? "" : " --out " + opt->out);
    const std::string base = std::filesystem::path(*config).parent_path().string();
    run_seismic_insitu(text, *config, base.empty() ? "." : base, *opt);
  });
});

}  // namespace
}  // namespace panoptes::app
