// The overhead meter's attribution (overhead.hpp): CPU during calls, Panoptes' threads between calls,
// the simulation's threads and the OpenMP team outside calls, and the report's wording.
#include "insitu/overhead.hpp"

#include <time.h>

#include <atomic>
#include <cstdlib>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <omp.h>

namespace panoptes::insitu {
namespace {

double thread_cpu() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Burns `seconds` of this thread's CPU (not wall time: the machine may be loaded).
void burn(double seconds) {
  const double end = thread_cpu() + seconds;
  volatile double x = 1;
  while (thread_cpu() < end)
    for (int i = 0; i < 1000; ++i) x = x * 1.0000001 + 1e-9;
}

TEST(OverheadMeter, CpuInsideCallsIsPanoptesAndOutsideIsTheSimulations) {
  OverheadMeter m;
  const RankOverhead r0 = m.read();
  {
    OverheadMeter::Scope call(m);
    burn(0.2);
  }
  const RankOverhead r1 = m.read();
  EXPECT_NEAR(r1.visualization_cpu_s - r0.visualization_cpu_s, 0.2, 0.05);
  burn(0.2);
  const RankOverhead r2 = m.read();
  EXPECT_NEAR(r2.visualization_cpu_s, r1.visualization_cpu_s, 0.01);
  EXPECT_NEAR(r2.simulation_cpu_s - r1.simulation_cpu_s, 0.2, 0.05);
  EXPECT_GE(r2.visualization_wall_s, 0.0);
  EXPECT_GE(r2.elapsed_wall_s, r2.visualization_wall_s);
}

TEST(OverheadMeter, ThreadStartedInACallIsPanoptesAlsoBetweenCalls) {
  // An encoder's or a pool's thread may keep working after the call that started it returned.
  OverheadMeter m;
  std::atomic<bool> go{false}, done{false}, quit{false};
  std::thread worker;
  {
    OverheadMeter::Scope call(m);
    burn(0.005);  // a call that does work (shorter ones are not looked at for new threads)
    worker = std::thread([&] {
      while (!go) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      burn(0.3);
      done = true;
      while (!quit) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    });
  }
  const RankOverhead before = m.read();
  go = true;
  while (!done) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_NEAR(m.read().visualization_cpu_s - before.visualization_cpu_s, 0.3, 0.06);  // read between calls
  { OverheadMeter::Scope call(m); }  // the next call charges what the thread did in between
  const RankOverhead after = m.read();
  EXPECT_NEAR(after.visualization_cpu_s - before.visualization_cpu_s, 0.3, 0.06);
  EXPECT_LT(after.simulation_cpu_s - before.simulation_cpu_s, 0.1);
  quit = true;
  worker.join();
}

TEST(OverheadMeter, SimulationThreadsAndTheOpenMPTeamAreNotAdopted) {
  // The team exists (a simulation's loop or an earlier test made it) or Panoptes' call creates it.
  OverheadMeter m;
  std::atomic<bool> quit{false};
  std::thread simulation_thread([&] {
    while (!quit) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  {
    OverheadMeter::Scope call(m);
#pragma omp parallel
    burn(0.01);
  }
  const double before = m.read().visualization_cpu_s;
  // Outside the calls the team runs the simulation's loops.
#pragma omp parallel
  burn(0.15);
  { OverheadMeter::Scope call(m); }
  EXPECT_LT(m.read().visualization_cpu_s - before, 0.05);
  quit = true;
  simulation_thread.join();
}

TEST(OverheadMeter, TheTeamsSpinAfterPanoptesLastLoopIsPanoptes) {
  // libgomp keeps the team spinning a few ms after a loop; after Panoptes' last loop of a call that
  // spin must not land in the simulation's share (a code without OpenMP loops would not have it).
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  if (policy && std::string(policy) == "active") GTEST_SKIP() << "OMP_WAIT_POLICY=active: the team never sleeps";
  if (omp_get_max_threads() < 2) GTEST_SKIP() << "a team of one thread does not spin";
  OverheadMeter m;
  for (int call = 0; call < 5; ++call) {
    {
      OverheadMeter::Scope scope(m);
#pragma omp parallel
      burn(0.005);
    }
    const RankOverhead before = m.read();
    std::this_thread::sleep_for(std::chrono::milliseconds(30));  // the "simulation" sleeps
    EXPECT_LT(m.read().simulation_cpu_s - before.simulation_cpu_s, 0.0015) << "call " << call;
  }
}

TEST(OverheadReport, OneRankStatesCpuAgainstTheSimulationsCpu) {
  const std::string s = overhead_report({{0, 25.8, 42.0, 12.3, 40.1}});
  EXPECT_NE(s.find("visualization used 0.61x the simulation's CPU time"), std::string::npos) << s;
  EXPECT_NE(s.find("visualization 25.80 CPU-s, simulation 42.00 CPU-s"), std::string::npos) << s;
  EXPECT_NE(s.find("wall time inside Panoptes 12.3 s of 40.1 s"), std::string::npos) << s;
}

TEST(OverheadReport, SeveralRanksGiveTheSpreadAndTheJobsTotal) {
  const std::string s = overhead_report({{0, 10, 20, 5, 30}, {1, 20, 20, 9, 30}, {2, 6, 30, 3, 30}});
  // Ratios 0.5, 1.0, 0.2; together (10 + 20 + 6) / (20 + 20 + 30) = 36 / 70.
  EXPECT_NE(s.find("min 0.20x, median 0.50x, max 1.00x over 3 ranks; all ranks together 0.51x"), std::string::npos)
      << s;
  EXPECT_NE(s.find("rank   1: visualization     20.00 CPU-s"), std::string::npos) << s;
  EXPECT_NE(overhead_report({{0, 1, 0, 1, 1}}).find("n/a (no simulation CPU time)"), std::string::npos);
}

}  // namespace
}  // namespace panoptes::insitu

namespace panoptes::insitu {
namespace {
TEST(OverheadMeter, AnEmptyCallIsCheap) {
  // Codes call panoptes_set_field and panoptes_process every step: the meter must not become an
  // overhead of its own (it was ~45 us per call while it listed the threads at every call).
  OverheadMeter m;
  { OverheadMeter::Scope call(m); }
  const double t0 = process_cpu_seconds();
  constexpr int kCalls = 2000;
  for (int i = 0; i < kCalls; ++i) OverheadMeter::Scope call(m);
  const double per_call = (process_cpu_seconds() - t0) / kCalls;
  EXPECT_LT(per_call, 20e-6);
  std::printf("an empty call costs %.1f us of CPU\n", per_call * 1e6);
}
}  // namespace
}  // namespace panoptes::insitu
