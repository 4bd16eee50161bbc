#include "core/image.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.hpp"
#include "core/png.hpp"

using namespace panoptes;

TEST(Image, PsnrOfIdenticalImagesIsInfinite) {
  Image a(8, 4, 3);
  for (std::size_t i = 0; i < a.pixels.size(); ++i) a.pixels[i] = std::uint8_t(i * 7);
  EXPECT_TRUE(std::isinf(psnr(a, a)));
}

TEST(Image, PsnrOfOneLevelErrorIsAbout48dB) {
  Image a(16, 16, 3), b(16, 16, 3);
  for (auto& p : b.pixels) p = 1;
  EXPECT_NEAR(psnr(a, b), 48.13, 0.01);
}

TEST(Image, PsnrRefusesDifferentSizes) { EXPECT_THROW(psnr(Image(2, 2), Image(3, 2)), Error); }

TEST(Png, RoundTripKeepsPixels) {
  Image a(5, 3, 4);
  for (std::size_t i = 0; i < a.pixels.size(); ++i) a.pixels[i] = std::uint8_t(i * 13);
  const auto path = (std::filesystem::temp_directory_path() / "panoptes_png_test.png").string();
  write_png(path, a);
  const Image b = read_png(path);
  EXPECT_EQ(b.width, 5);
  EXPECT_EQ(b.height, 3);
  EXPECT_EQ(b.pixels, a.pixels);
  std::filesystem::remove(path);
}

TEST(Png, MissingFileNamesThePath) {
  try {
    read_png("/nonexistent/panoptes.png");
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/panoptes.png"), std::string::npos);
  }
}
