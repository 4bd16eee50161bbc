#include "core/dims_text.hpp"

#include <gtest/gtest.h>

using panoptes::parse_dims_text;

TEST(DimsText, ParsesSizesAndLattices) {
  EXPECT_EQ(parse_dims_text("920x896", 2, 5), (std::vector<int>{920, 896}));
  EXPECT_EQ(parse_dims_text("4x4x3", 3, 4), (std::vector<int>{4, 4, 3}));
  EXPECT_EQ(parse_dims_text("0x07", 2, 5), (std::vector<int>{0, 7}));  // ranges are the caller's to check
}

TEST(DimsText, RefusesAnythingElse) {
  for (const char* bad : {"", "920", "920x", "x896", "920x896x", "920X896", " 920x896", "920x896 ", "92 0x896",
                          "-1x5", "+1x5", "1.5x2", "123456x2", "920x896x3"})
    EXPECT_FALSE(parse_dims_text(bad, 2, 5)) << bad;
  EXPECT_FALSE(parse_dims_text("4x4", 3, 4));
  EXPECT_FALSE(parse_dims_text("12345x1x1", 3, 4));
}
