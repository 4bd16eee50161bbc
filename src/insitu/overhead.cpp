#include "insitu/overhead.hpp"

#include <dirent.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <omp.h>

namespace panoptes::insitu {

namespace {

// Panoptes' CPU of every session of the process, in ns: the simulation's CPU is the process's minus
// this, so a program that runs sessions one after the other does not count the first one's
// visualization as the second one's simulation.
std::atomic<std::int64_t> g_panoptes_cpu_ns{0};

void charge_global(double seconds) { g_panoptes_cpu_ns.fetch_add(std::int64_t(seconds * 1e9)); }
double global_panoptes_cpu() { return double(g_panoptes_cpu_ns.load()) * 1e-9; }

double wall_seconds() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

int current_tid() { return int(syscall(SYS_gettid)); }

// The CPU clock of another thread of this process, by its kernel thread id: the clock id glibc's
// pthread_getcpuclockid builds from a tid (MAKE_THREAD_CPUCLOCK(tid, CPUCLOCK_SCHED), a stable kernel
// ABI), since threads started inside FFmpeg or x264 have no pthread_t we could ask for. Nanosecond
// scheduler time, as getrusage sums it. Negative when the thread has exited.
double thread_cpu_seconds(int tid) {
  const clockid_t clock = clockid_t((~unsigned(tid)) << 3) | 6;  // per-thread (4) | CPUCLOCK_SCHED (2)
  timespec t{};
  if (clock_gettime(clock, &t) != 0) return -1;
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

double process_cpu_seconds() {
  // The scheduler's CPU time of every thread of the process, exited ones included: the sum getrusage
  // (RUSAGE_SELF) splits into user and system time, and what wait4 and `time` report for the process.
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

OverheadMeter::OverheadMeter() : created_wall_(wall_seconds()) {
  // Threads running before the session exists are the simulation's (its OpenMP team, MPI's threads).
  for (Tid t : threads()) known_[t] = true;
}

double OverheadMeter::wall_now() const { return wall_seconds(); }

std::vector<OverheadMeter::Tid> OverheadMeter::threads() const {
  std::vector<Tid> out;
  DIR* d = opendir("/proc/self/task");
  if (!d) return out;
  while (dirent* e = readdir(d)) {
    char* end = nullptr;
    const long v = std::strtol(e->d_name, &end, 10);
    if (end != e->d_name && *end == '\0' && v > 0) out.push_back(Tid(v));
  }
  closedir(d);
  return out;
}

void OverheadMeter::enter() {
  if (depth_++ > 0) return;
  // First the clocks, so that the bookkeeping below counts as Panoptes' too.
  entered_cpu_ = process_cpu_seconds();
  entered_wall_ = wall_now();
  if (!owned_.empty()) charge_outside();
  // Threads the simulation started since the last look are its own. Listing /proc/self/task costs
  // ~20 us, so codes that call every step (panoptes_set_field + panoptes_process: 2 calls of ~1 us) look
  // at most every kListEvery; a thread the code starts just before a call may be taken for Panoptes'.
  if (entered_wall_ - listed_wall_ > kListEvery) {
    for (Tid t : threads()) known_.emplace(t, true);
    listed_wall_ = entered_wall_;
  }
}

void OverheadMeter::leave() {
  if (depth_ == 0 || --depth_ > 0) return;
  // Only a call that did work (a snapshot, the construction) can have started threads or left the
  // OpenMP team spinning; the per-step calls skip both (an empty call then costs ~2 us, not ~45).
  if (wall_now() - entered_wall_ > kLongCall) {
    adopt_new_threads();
    settle_team();
  }
  const double cpu = process_cpu_seconds() - entered_cpu_;
  inside_cpu_ += cpu;
  charge_global(cpu);
  const double now = wall_now();
  inside_wall_ += now - entered_wall_;
  if (!owned_.empty()) baseline_owned();
}

void OverheadMeter::adopt_new_threads() {
  std::vector<Tid> fresh;
  for (Tid t : threads())
    if (!known_.count(t)) fresh.push_back(t);
  if (fresh.empty() && team_known_) return;
  // The OpenMP team is shared with the simulation (see the header): its threads are not adopted even
  // when Panoptes' first parallel loop created them. Asking the team for its thread ids costs one
  // parallel region, only on the first call and on calls that started threads.
  std::vector<Tid> team(std::size_t(omp_get_max_threads()), 0);
  const Tid caller = current_tid();
#pragma omp parallel
  {
    const int i = omp_get_thread_num();
    if (i < int(team.size())) team[std::size_t(i)] = current_tid();
  }
  team_.clear();
  for (Tid t : team)
    if (t != 0 && t != caller) team_.push_back(t);
  team_known_ = true;
  for (Tid t : fresh) {
    known_[t] = true;
    if (std::find(team.begin(), team.end(), t) == team.end()) owned_[t] = 0;
  }
  for (Tid t : threads()) known_.emplace(t, true);
  listed_wall_ = wall_now();
}

namespace {
// 'R' (running or runnable), 'S' (sleeping), ...; 0 when the thread is gone.
char thread_state(int tid) {
  char path[64];
  std::snprintf(path, sizeof path, "/proc/self/task/%d/stat", tid);
  std::FILE* f = std::fopen(path, "r");
  if (!f) return 0;
  char buf[512];
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  buf[n] = '\0';
  const char* close = std::strrchr(buf, ')');  // the command name may hold spaces and parentheses
  return close && close[1] == ' ' ? close[2] : 0;
}

bool active_wait_policy() {
  const char* p = std::getenv("OMP_WAIT_POLICY");
  return p && (std::strcmp(p, "active") == 0 || std::strcmp(p, "ACTIVE") == 0);
}
}  // namespace

void OverheadMeter::settle_team() {
  // After a parallel loop libgomp keeps the team's threads spinning (GOMP_SPINCOUNT, default 300000
  // iterations: 2-6 ms of CPU per thread on the 2-core EPYC) before they sleep. After Panoptes' last loop
  // of a call that spin would run on past the call's end and count as the simulation's: measured with
  // capi.overhead_vs_os, ~0.05 CPU-s of a 0.85 CPU-s code, the line 10-20 % low. So the call ends
  // once the team sleeps (its threads' state in /proc): the spin lands inside the call, and the wait
  // costs no CPU of its own (this thread sleeps). Bounded, for a team that does not go to sleep: a
  // simulation that calls from inside its own parallel region, or OMP_WAIT_POLICY=active, where the
  // team spins until the next loop whoever runs it (not waited for at all).
  if (team_.empty() || active_wait_policy()) return;
  constexpr double kSettleMax = 0.02;  // s
  const double start = wall_now();
  for (;;) {
    bool spinning = false;
    for (Tid t : team_)
      if (thread_state(t) == 'R') spinning = true;
    if (!spinning || wall_now() - start > kSettleMax) return;
    const timespec pause{0, 200000};  // 0.2 ms
    nanosleep(&pause, nullptr);
  }
}

void OverheadMeter::baseline_owned() {
  for (auto it = owned_.begin(); it != owned_.end();) {
    const double c = thread_cpu_seconds(it->first);
    if (c < 0) {
      it = owned_.erase(it);  // exited during the call: its CPU is in the process CPU of the call
    } else {
      it->second = c;
      ++it;
    }
  }
}

void OverheadMeter::charge_outside() {
  double sum = 0;
  for (auto it = owned_.begin(); it != owned_.end();) {
    const double c = thread_cpu_seconds(it->first);
    if (c < 0) {
      // Exited between the calls: its last stretch is not readable any more (counted as the
      // simulation's); Panoptes' threads end inside finalize, where the process CPU counts them.
      it = owned_.erase(it);
      continue;
    }
    sum += std::max(0.0, c - it->second);
    it->second = c;
    ++it;
  }
  outside_cpu_ += sum;
  charge_global(sum);
}

void OverheadMeter::stop() {
  if (stopped_) return;
  if (depth_ == 0) charge_outside();
  final_ = read_now();
  stopped_ = true;
}

RankOverhead OverheadMeter::read() const { return stopped_ ? final_ : read_now(); }

RankOverhead OverheadMeter::read_now() const {
  const double process = process_cpu_seconds(), now = wall_now();
  // A call still open (the C API prints the report inside panoptes_finalize) counts up to now; between
  // calls, what Panoptes' threads did since the last one.
  const double open_cpu = depth_ > 0 ? process - entered_cpu_ : 0;
  double pending = 0;
  if (depth_ == 0)
    for (const auto& [tid, at_leave] : owned_) {
      const double c = thread_cpu_seconds(tid);
      if (c >= 0) pending += std::max(0.0, c - at_leave);
    }
  RankOverhead r;
  r.visualization_cpu_s = inside_cpu_ + outside_cpu_ + open_cpu + pending;
  r.simulation_cpu_s = std::max(0.0, process - (global_panoptes_cpu() + open_cpu + pending));
  r.visualization_wall_s = inside_wall_ + (depth_ > 0 ? now - entered_wall_ : 0);
  r.elapsed_wall_s = now - created_wall_;
  return r;
}

std::string overhead_report(const std::vector<RankOverhead>& ranks) {
  if (ranks.empty()) return "";
  std::vector<double> x;
  double vis = 0, sim = 0;
  for (const RankOverhead& r : ranks) {
    x.push_back(r.multiple());
    vis += r.visualization_cpu_s;
    sim += r.simulation_cpu_s;
  }
  std::vector<double> sorted = x;
  std::sort(sorted.begin(), sorted.end());
  char buf[512];
  auto times = [](double v) {
    char b[64];
    if (!std::isfinite(v)) return std::string("n/a (no simulation CPU time)");
    std::snprintf(b, sizeof b, "%.2fx", v);
    return std::string(b);
  };
  if (ranks.size() == 1) {
    const RankOverhead& r = ranks[0];
    std::snprintf(buf, sizeof buf,
                  "in-situ overhead: visualization used %s the simulation's CPU time (visualization %.2f CPU-s, "
                  "simulation %.2f CPU-s, all threads; wall time inside Panoptes %.1f s of %.1f s)\n",
                  times(x[0]).c_str(), r.visualization_cpu_s, r.simulation_cpu_s, r.visualization_wall_s,
                  r.elapsed_wall_s);
    return buf;
  }
  const std::size_t n = sorted.size();
  const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  std::snprintf(buf, sizeof buf,
                "in-situ overhead: visualization CPU time / simulation CPU time per rank: min %s, median %s, max %s "
                "over %zu ranks; all ranks together %s (visualization %.2f CPU-s, simulation %.2f CPU-s)\n",
                times(sorted.front()).c_str(), times(median).c_str(), times(sorted.back()).c_str(), n,
                times(sim > 0 ? vis / sim : INFINITY).c_str(), vis, sim);
  std::string out = buf;
  // Every rank when they fit on a screen; otherwise the extremes are in the line above.
  if (ranks.size() <= 16)
    for (const RankOverhead& r : ranks) {
      std::snprintf(buf, sizeof buf,
                    "  rank %3d: visualization %9.2f CPU-s, simulation %9.2f CPU-s -> %s (wall inside Panoptes "
                    "%.1f s of %.1f s)\n",
                    r.rank, r.visualization_cpu_s, r.simulation_cpu_s, times(r.multiple()).c_str(),
                    r.visualization_wall_s, r.elapsed_wall_s);
      out += buf;
    }
  return out;
}

}  // namespace panoptes::insitu
