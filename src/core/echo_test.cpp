#include "core/echo.hpp"

#include <gtest/gtest.h>

using panoptes::echo;

TEST(Echo, ShortValuesAreKept) { EXPECT_EQ(echo("phi_s iso 0.2"), "phi_s iso 0.2"); }

TEST(Echo, LongValuesAreCutAndSayTheirSize) {
  const std::string big(1 << 20, 'a');
  const std::string e = echo(big);
  EXPECT_LT(e.size(), 120u);
  EXPECT_EQ(e, std::string(80, 'a') + "... (1048576 bytes)");
}

TEST(Echo, ControlCharactersStayOnOneLine) {
  EXPECT_EQ(echo("a\nb\tc\\d\x01"), "a\\nb\\tc\\\\d\\x01");
}

TEST(Echo, NeverCutsAUtf8Character) {
  const std::string s = std::string(79, 'x') + "\xc3\xa9" + "tail";  // é straddles byte 80
  EXPECT_EQ(echo(s), std::string(79, 'x') + "... (" + std::to_string(s.size()) + " bytes)");
}
