#include "core/parallel_for.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace panoptes {
namespace {

TEST(ParallelFor, ThreadsAreAtLeastOneAndAtMostTheItems) {
  EXPECT_EQ(parallel_threads(10, 3), 3);
  EXPECT_EQ(parallel_threads(2, 8), 2);
  EXPECT_EQ(parallel_threads(0, 8), 1);
  EXPECT_GE(parallel_threads(1000, 0), 1);
  EXPECT_LE(parallel_threads(1000, 0), 1000);
}

TEST(ParallelFor, CallsEveryIndexOnceOnSeveralThreads) {
  for (int threads : {0, 1, 3, 16}) {
    std::vector<std::atomic<int>> calls(1000);
    std::mutex mutex;
    std::set<std::thread::id> ids;
    parallel_for(std::int64_t(calls.size()), threads, [&](std::int64_t i) {
      ++calls[std::size_t(i)];
      std::lock_guard lock(mutex);
      ids.insert(std::this_thread::get_id());
    });
    for (const auto& c : calls) ASSERT_EQ(c.load(), 1) << threads << " threads";
    EXPECT_LE(int(ids.size()), parallel_threads(1000, threads));
    if (threads == 1) {
      EXPECT_EQ(*ids.begin(), std::this_thread::get_id());  // the caller works
    }
  }
  parallel_for(0, 4, [](std::int64_t) { FAIL() << "no index in an empty range"; });
}

TEST(ParallelFor, RethrowsTheFirstErrorAndStartsNoFurtherIndex) {
  // Each index takes 1 ms, so without the stop the other threads would need ~7 s for the rest: the
  // thread that throws at index 10 would have to be kept off a core that long for this to fail by load
  // (with trivial bodies the others finished all 100,000 indices while it waited: a flaky test).
  std::atomic<std::int64_t> started{0};
  try {
    parallel_for(20000, 4, [&](std::int64_t i) {
      ++started;
      if (i == 10) throw std::runtime_error("index 10");
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "index 10");
  }
  const std::int64_t at_return = started.load();
  EXPECT_LT(at_return, 20000);
  // Nothing is still running or starts after the call returned.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(started.load(), at_return);
}

TEST(ParallelFor, WatchRunsOnTheCallerWhileOthersWork) {
  std::atomic<int> done{0};
  int watched = 0;
  const auto caller = std::this_thread::get_id();
  std::atomic<bool> caller_worked{false};
  parallel_for(
      8, 2,
      [&](std::int64_t) {
        if (std::this_thread::get_id() == caller) caller_worked = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ++done;
      },
      [&] {
        ++watched;
        return true;
      },
      std::chrono::milliseconds(1));
  EXPECT_EQ(done.load(), 8);
  EXPECT_GE(watched, 1);
  EXPECT_FALSE(caller_worked.load());
}

TEST(ParallelFor, WatchSeesTheErrorAndStops) {
  EXPECT_THROW(parallel_for(
                   4, 2, [](std::int64_t i) { if (i == 0) throw std::runtime_error("first"); }, [] { return true; },
                   std::chrono::milliseconds(1)),
               std::runtime_error);
}

}  // namespace
}  // namespace panoptes
