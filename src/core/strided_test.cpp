// strided_reach: the reach of a strided 3-D array, every product and sum checked (issue 42, point 6).
#include "core/strided.hpp"

#include <gtest/gtest.h>

#include <climits>

using namespace panoptes;

TEST(StridedReach, ContiguousNegativeAndShiftedArrays) {
  const auto c = strided_reach({8, 7, 4}, {1, 8, 56}, 4);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->lo, 0);
  EXPECT_EQ(c->hi, 223);
  const auto r = strided_reach({8, 7, 4}, {-1, 8, 56}, 4);  // x reversed: 7 elements before data
  ASSERT_TRUE(r);
  EXPECT_EQ(r->lo, -7);
  EXPECT_EQ(r->hi, 216);
  const auto g = strided_reach({8, 7, 4}, {1, 8, 56}, 4, {1, 1, 1});  // from a ghost-shifted first point
  ASSERT_TRUE(g);
  EXPECT_EQ(g->lo, -65);
  EXPECT_EQ(g->hi, 223 - 65);
  const auto one = strided_reach({1, 1, 1}, {LLONG_MAX, LLONG_MIN, 0}, 8);  // one point reaches nothing
  ASSERT_TRUE(one);
  EXPECT_EQ(one->hi, 0);
}

TEST(StridedReach, OverflowsAreRefusedNotWrapped) {
  EXPECT_FALSE(strided_reach({8, 8, 8}, {1, 8, LLONG_MAX / 7 + 1}, 1));    // the product wraps
  EXPECT_FALSE(strided_reach({8, 8, 8}, {1, 8, 1LL << 62}, 4));           // 2^64 bytes: plane 0 again
  EXPECT_FALSE(strided_reach({2, 2, 2}, {LLONG_MAX / 2, LLONG_MAX / 2, LLONG_MAX / 2}, 1));  // the sum wraps
  EXPECT_FALSE(strided_reach({8, 8, 8}, {1, 8, 1LL << 61}, 8));           // elements fit, bytes do not
  EXPECT_FALSE(strided_reach({2, 2, 2}, {-(LLONG_MAX / 2), LLONG_MAX / 2, 2}, 1, {1, 0, 0}));  // hi - shift wraps
  EXPECT_TRUE(strided_reach({8, 8, 8}, {1, 8, 1LL << 58}, 4));
}
