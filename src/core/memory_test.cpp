#include "core/memory.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

#include "core/error.hpp"

namespace panoptes {
namespace {

TEST(Memory, AvailableMemoryIsKnownOnLinuxAndBelowPhysical) {
  const MemoryLimit m = available_memory();
  ASSERT_GT(m.bytes, 0) << "no MemAvailable and no cgroup limit";
  EXPECT_FALSE(m.source.empty());
  EXPECT_LT(m.bytes, 1e15);
}

TEST(Memory, EnvironmentLimitReplacesTheMachines) {
  ::setenv("PANOPTES_MEMORY_LIMIT", "1.5G", 1);
  const MemoryLimit m = available_memory();
  ::unsetenv("PANOPTES_MEMORY_LIMIT");
  EXPECT_DOUBLE_EQ(m.bytes, 1.5e9);
  EXPECT_EQ(m.source, "PANOPTES_MEMORY_LIMIT");
}

TEST(Memory, RefusalNamesBothNumbersAndTheOverride) {
  MemoryEstimate e;
  e.add("solver arrays", 80e9);
  e.add("receiver traces", 16e9);
  e.add("tiny", 1);
  const MemoryLimit limit{8e9, "MemAvailable"};
  const std::string why = memory_refusal(e, limit, 2, "this run", "pass --force");
  EXPECT_NE(why.find("96.0 GB"), std::string::npos) << why;
  EXPECT_NE(why.find("solver arrays 80.0 GB"), std::string::npos) << why;
  EXPECT_NE(why.find("4.0 GB available"), std::string::npos) << why;
  EXPECT_NE(why.find("2 ranks"), std::string::npos) << why;
  EXPECT_NE(why.find("pass --force"), std::string::npos) << why;
  EXPECT_EQ(why.find("tiny"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos);
  EXPECT_THROW(check_memory(e, limit, 2, "this run", "pass --force"), Error);
  EXPECT_NO_THROW(check_memory(e, MemoryLimit{200e9, "x"}, 1, "this run", "x"));
  EXPECT_NO_THROW(check_memory(e, MemoryLimit{}, 1, "this run", "x"));  // unknown limit: no check
}

TEST(Memory, CheckedProductRefusesOverflowAndLimits) {
  EXPECT_EQ(checked_product(130, 3, "streams"), 390);
  EXPECT_THROW(checked_product(std::int64_t(1) << 40, std::int64_t(1) << 30, "pixels"), Error);
  EXPECT_THROW(checked_product(100000, 100000, "streams", 1 << 30), Error);
  EXPECT_THROW(checked_product(-1, 5, "streams"), Error);
}

TEST(Memory, FormatBytes) {
  EXPECT_EQ(format_bytes(512), "512 B");
  EXPECT_EQ(format_bytes(1.8e9), "1.8 GB");
}

TEST(Memory, OpenFileLimitIsPositiveOrUnlimited) {
  const long long n = open_file_limit();
  EXPECT_TRUE(n == -1 || n >= 64) << n;
}

}  // namespace
}  // namespace panoptes
