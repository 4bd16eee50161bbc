#include "core/utc_time.hpp"

#include <gtest/gtest.h>

#include <regex>

namespace panoptes {
namespace {

TEST(UtcTime, Iso8601InUtc) {
  EXPECT_EQ(utc_iso8601(0), "1970-01-01T00:00:00Z");
  EXPECT_EQ(utc_iso8601(1795214400), "2026-11-20T22:40:00Z");
  EXPECT_TRUE(std::regex_match(utc_now_iso8601(), std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
}

}  // namespace
}  // namespace panoptes
