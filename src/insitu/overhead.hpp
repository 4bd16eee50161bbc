#pragma once
// The in-situ overhead as the operating system counts it: CPU time of every thread of the process,
// split between Panoptes and the simulation that calls it (issue 41, point 7).
//
// Wall time inside the session's calls under-reports the cost: Panoptes renders and encodes on every
// OpenMP thread (and x264 may run threads of its own), while a simulation may use one core per rank, so
// a second of Panoptes wall time can be two CPU-seconds. What a job is charged, and what `time` or a
// batch system's accounting prints, is CPU time; the line says that.
//
// Attribution (per process, i.e. per MPI rank):
//   * Panoptes: the process CPU (user + system of all threads, also of threads that have exited) accrued
//     while a call runs (the session's construction, snapshot, finalize; the C API brackets every call
//     on its handle), plus the CPU that threads Panoptes started consume between its calls (encoder
//     threads, thread pools). A thread is Panoptes' when it first appears during one of its calls that
//     did work and is not a member of the OpenMP team (found with /proc/self/task and read with a
//     per-thread CPU clock; without /proc, only the first part is counted).
//   * The simulation: the rest of the process CPU since the process started (its setup and MPI_Init
//     included), as `time` would count the code without Panoptes.
//   * OpenMP threads belong to whoever runs them at the moment: the team is shared (Panoptes' parallel
//     loops reuse the simulation's threads, or the simulation later reuses the team Panoptes' first loop
//     created), so its CPU during a Panoptes call is Panoptes' — also a simulation thread that spins
//     waiting (OMP_WAIT_POLICY, GOMP_SPINCOUNT) while Panoptes runs, which is CPU Panoptes' call caused —
//     and outside the calls it is the simulation's. The team's spin after Panoptes' last parallel loop
//     of a call (libgomp: GOMP_SPINCOUNT iterations, a few ms) is made to fall inside the call: a call
//     that did work returns once the team sleeps (settle_team). With OMP_WAIT_POLICY=active the team
//     never sleeps and is not waited for: a code without OpenMP of its own then has Panoptes' team
//     spinning between calls counted as its own.
//   * Other threads of the simulation that run during a Panoptes call (an I/O or communication thread
//     of its own) are counted as Panoptes'; a code that keeps such threads busy over-reads the ratio.
//     The simulation's loops running slower after a snapshot (caches Panoptes evicted) count as its own.
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace panoptes::insitu {

/// One rank's in-situ overhead: CPU time (all threads) spent on visualization and the rest of the
/// process's CPU time (the simulation's), with the wall time inside the session's calls beside it.
struct RankOverhead {
  int rank = 0;
  double visualization_cpu_s = 0;  ///< process CPU inside the session's calls + Panoptes' threads outside
  double simulation_cpu_s = 0;     ///< the rest of the process CPU since the process started
  double visualization_wall_s = 0; ///< wall time inside the session's calls
  double elapsed_wall_s = 0;       ///< wall time from the session's creation to finalize
  /// Visualization CPU as a multiple of simulation CPU (+inf without simulation CPU).
  double multiple() const { return simulation_cpu_s > 0 ? visualization_cpu_s / simulation_cpu_s : INFINITY; }
};

/// The end-of-run lines printed by `panoptes run` and the C API: visualization CPU time as a multiple
/// of simulation CPU time, one line for one rank; for several, min / median / max over ranks, all
/// ranks together (what the OS counts for the whole job) and (up to 16 ranks) a row per rank.
std::string overhead_report(const std::vector<RankOverhead>& ranks);

/// Process CPU time (all threads, exited ones included) in seconds: getrusage(RUSAGE_SELF)'s user + system.
double process_cpu_seconds();

/// Measures one session's share of the process CPU. enter()/leave() bracket every session call on the
/// calling thread (nested calls count once); not thread-safe (a session's calls are made in order).
class OverheadMeter {
 public:
  OverheadMeter();
  OverheadMeter(const OverheadMeter&) = delete;
  OverheadMeter& operator=(const OverheadMeter&) = delete;

  void enter();
  void leave();
  /// Freezes the run's end (finalize; also inside an enclosing call, which counts up to here): later
  /// readings report the CPU and wall time up to this point.
  void stop();

  /// Counts one call, also when it throws.
  class Scope {
   public:
    explicit Scope(OverheadMeter& m) : m_(m) { m_.enter(); }
    ~Scope() { m_.leave(); }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    OverheadMeter& m_;
  };

  /// This session's overhead so far (or up to stop()); rank is left 0.
  RankOverhead read() const;
  bool inside() const { return depth_ > 0; }

 private:
  using Tid = int;
  double wall_now() const;
  RankOverhead read_now() const;
  std::vector<Tid> threads() const;   // the process's threads now (empty without /proc)
  void adopt_new_threads();           // at leave(): threads started during the call, minus the OpenMP team
  void charge_outside();              // at enter() / stop(): Panoptes threads' CPU since the last leave()
  void baseline_owned();              // at leave(): their CPU now
  void settle_team();                 // at leave(): until the OpenMP team stops spinning (bounded)

  static constexpr double kListEvery = 0.01;  // s between looks at the process's threads
  static constexpr double kLongCall = 0.001;  // s: shorter calls start no threads and run no parallel loop
  int depth_ = 0;
  double listed_wall_ = -1e300;
  double created_wall_ = 0;
  double entered_wall_ = 0;
  double entered_cpu_ = 0;
  double inside_wall_ = 0;
  double inside_cpu_ = 0;   // process CPU during the calls
  double outside_cpu_ = 0;  // Panoptes' threads between the calls
  std::unordered_map<Tid, double> owned_;     // Panoptes' threads -> their CPU at the last leave()
  std::unordered_map<Tid, bool> known_;       // every thread seen, so none is adopted twice
  std::vector<Tid> team_;                     // the OpenMP team's threads other than the caller
  bool team_known_ = false;
  bool stopped_ = false;
  RankOverhead final_;  // read at stop()
};

}  // namespace panoptes::insitu
