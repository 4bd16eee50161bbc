// Issue #31, row 11: every per-item table of a run is in its memory estimate, and every file a run
// reads is refused at once when it is a FIFO or a device.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "seismic/medium.hpp"
#include "seismic/resources.hpp"

using namespace panoptes;
using namespace panoptes::seismic;

namespace {

SolverConfig small_run(int sources, int receivers) {
  SolverConfig c;
  c.grid = {64, 64, 64, 100.0};
  c.medium = MediumSpec::homogeneous(2500, 5000, 3000);
  c.steps = 10;
  for (int s = 0; s < sources; ++s)
    c.sources.push_back(SourceSpec::explosion({3200.0, 3200.0, 3200.0}, 1e15, SourceTimeFunction::ricker(2.0)));
  for (int r = 0; r < receivers; ++r) c.receivers.push_back({"r" + std::to_string(r), {1000.0, 1000.0, 0.0}});
  return c;
}

double item(const MemoryEstimate& e, const std::string& name) {
  for (const auto& [what, bytes] : e.items)
    if (what == name) return bytes;
  return 0;
}

}  // namespace

TEST(SeismicResources, SourcesAndReceiversAreCounted) {
  const double none = estimate_solver_memory(small_run(0, 0), 1).total();
  const MemoryEstimate many = estimate_solver_memory(small_run(100000, 0), 1);
  // The case: 10^5 sources grew to 8.8 GB under PANOPTES_MEMORY_LIMIT=6G.
  EXPECT_GT(item(many, "source tables"), 6e9);
  EXPECT_GT(many.total() - none, 6e9);
  const MemoryEstimate receivers = estimate_solver_memory(small_run(0, 100000), 1);
  EXPECT_GT(item(receivers, "receiver tables"), 1e5 * 100);
}

TEST(SeismicResources, AMediumFileThatIsAFifoIsRefusedAtOnce) {
  const auto fifo = std::filesystem::temp_directory_path() / ("panoptes-medium-fifo-" + std::to_string(::getpid()));
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  std::string message = "<no error>";
  try {
    read_npy_planes(fifo.string(), 4, 4, 4, 0, 4);
  } catch (const Error& e) {
    message = e.what();
  }
  std::filesystem::remove(fifo);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_NE(message.find("FIFO"), std::string::npos) << message;
}
