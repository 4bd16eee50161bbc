// The C API's non-uniform grid calls (issue 33), one process: a Yin-Yang grid with both patches bound
// from one process renders and records its kind in the manifest; bad coordinates, patches and
// missing blocks are refused with codes and messages.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "panoptes.h"
#include "panoptes.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

std::string config(const std::string& dir) {
  return "[output]\ndir = \"" + dir + "\"\n[image]\nwidth = 32\nheight = 32\n[rig]\nspec = \"fibonacci:2\"\n"
         "[schedule]\nevery_steps = 1\n[[task]]\nname = \"T\"\ntype = \"volume\"\nfield = \"T\"\n"
         "preset = \"p-wave\"\nrelative = false\nwindow = [0.0, 1.0]\n";
}

class CapiGrid : public ::testing::Test {
 protected:
  void SetUp() override {
    panoptes_set_error_output(PANOPTES_ERRORS_NONE);
    dir_ = std::filesystem::temp_directory_path() /
           ("panoptes_capi_grid_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    ASSERT_EQ(panoptes_create(config(dir_.string()).c_str(), 0, PANOPTES_COMM_WORLD, &s_), PANOPTES_OK) << panoptes_last_error();
    for (int i = 0; i < 6; ++i) r_.push_back(0.4 + 0.12 * i);
    // A Yin-Yang patch: θ ∈ [π/4 − 2δ, 3π/4 + 2δ], φ ∈ [−3π/4 − 2δ', 3π/4 + 2δ'].
    const double dt = (kPi / 2) / 11, dp = (1.5 * kPi) / 31;
    for (int j = 0; j < 16; ++j) t_.push_back(kPi / 4 - 2 * dt + j * dt);
    for (int k = 0; k < 36; ++k) p_.push_back(-0.75 * kPi - 2 * dp + k * dp);
  }
  void TearDown() override {
    panoptes_destroy(s_);
    std::filesystem::remove_all(dir_);
    panoptes_set_error_output(PANOPTES_ERRORS_ALL);
  }
  std::string manifest() const {
    std::ifstream in(dir_ / "panoptes.json");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  panoptes_session* s_ = nullptr;
  std::filesystem::path dir_;
  std::vector<double> r_, t_, p_;
};

TEST_F(CapiGrid, YinYangFromOneProcessRendersAndIsRecorded) {
  const int dims[3] = {6, 16, 36}, zero[3] = {0, 0, 0};
  ASSERT_EQ(panoptes_set_grid_yinyang(s_, dims, r_.data(), t_.data(), p_.data()), PANOPTES_OK) << panoptes_last_error();
  ASSERT_EQ(panoptes_set_resample(s_, 40, 0.0), PANOPTES_OK) << panoptes_last_error();
  // The world field |x|: Yang's frame has x' = −x, so both patches hold |x| of their own frame.
  std::vector<double> yin, yang;
  for (int k = 0; k < 36; ++k)
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 6; ++i) {
        const double x = r_[std::size_t(i)] * std::sin(t_[std::size_t(j)]) * std::cos(p_[std::size_t(k)]);
        yin.push_back(std::fabs(x));
        yang.push_back(std::fabs(x));
      }
  for (int patch : {0, 1}) {
    ASSERT_EQ(panoptes_set_patch(s_, patch), PANOPTES_OK) << panoptes_last_error();
    ASSERT_EQ(panoptes_set_block(s_, zero, dims, zero, zero), PANOPTES_OK);
    std::vector<double>& v = patch == 0 ? yin : yang;
    ASSERT_EQ(panoptes_set_field_n(s_, "T", v.data(), PANOPTES_FLOAT64, nullptr, (long long)v.size()), PANOPTES_OK)
        << panoptes_last_error();
  }
  ASSERT_EQ(panoptes_snapshot(s_, 0.0), PANOPTES_OK) << panoptes_last_error();
  ASSERT_EQ(panoptes_snapshot(s_, 1.0), PANOPTES_OK) << panoptes_last_error();
  ASSERT_EQ(panoptes_finalize(s_), PANOPTES_OK) << panoptes_last_error();
  const std::string m = manifest();
  EXPECT_NE(m.find("\"grid\":\"yinyang 6x16x36, r in [0.4, 1], 2 patches\""), std::string::npos) << m.substr(0, 600);
  EXPECT_NE(m.find("\"dims\":[40,40,40]"), std::string::npos) << m.substr(0, 600);
  // After the first snapshot a patch with a block may be selected again (to re-bind its fields), but
  // no block may change.
  EXPECT_EQ(panoptes_set_patch(s_, 0), PANOPTES_OK) << panoptes_last_error();
  EXPECT_EQ(panoptes_set_block(s_, zero, dims, zero, zero), PANOPTES_ERROR_USAGE);
}

// Issue 42, point 7: a rank holding both patches re-binds each patch's fields every step. Before,
// panoptes_set_patch was refused after the first snapshot, set_field bound only the selected patch
// (Yang), and Yin rendered step 0's array without an error. Here only Yin changes at step 1 (x3):
// the frame's reference (99.9th percentile, per snapshot) must follow it.
TEST_F(CapiGrid, BothPatchesOfOneRankAreReboundEveryStep) {
  panoptes_destroy(s_);
  const std::string relative = "[output]\ndir = \"" + dir_.string() + "\"\n[image]\nwidth = 32\nheight = 32\n[rig]\n"
                               "spec = \"fibonacci:2\"\n[render]\nreference = \"snapshot\"\n[schedule]\nevery_steps = 1\n"
                               "[[task]]\nname = \"T\"\ntype = \"volume\"\nfield = \"T\"\npreset = \"p-wave\"\n";
  ASSERT_EQ(panoptes_create(relative.c_str(), 0, PANOPTES_COMM_WORLD, &s_), PANOPTES_OK) << panoptes_last_error();
  const int dims[3] = {6, 16, 36}, zero[3] = {0, 0, 0};
  ASSERT_EQ(panoptes_set_grid_yinyang(s_, dims, r_.data(), t_.data(), p_.data()), PANOPTES_OK) << panoptes_last_error();
  ASSERT_EQ(panoptes_set_resample(s_, 40, 0.0), PANOPTES_OK) << panoptes_last_error();
  std::vector<double> yin0, yang, yin1;
  for (int k = 0; k < 36; ++k)
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 6; ++i) {
        const double x = r_[std::size_t(i)] * std::sin(t_[std::size_t(j)]) * std::cos(p_[std::size_t(k)]);
        yin0.push_back(std::fabs(x));
        yang.push_back(std::fabs(x));
        yin1.push_back(3 * std::fabs(x));  // a new array, as a code's next step
      }
  for (int patch : {0, 1}) {
    ASSERT_EQ(panoptes_set_patch(s_, patch), PANOPTES_OK) << panoptes_last_error();
    ASSERT_EQ(panoptes_set_block(s_, zero, dims, zero, zero), PANOPTES_OK);
    std::vector<double>& v = patch == 0 ? yin0 : yang;
    ASSERT_EQ(panoptes_set_field_n(s_, "T", v.data(), PANOPTES_FLOAT64, nullptr, (long long)v.size()), PANOPTES_OK);
  }
  ASSERT_EQ(panoptes_snapshot(s_, 0.0), PANOPTES_OK) << panoptes_last_error();
  ASSERT_EQ(panoptes_set_patch(s_, 0), PANOPTES_OK) << panoptes_last_error();
  EXPECT_EQ(panoptes_set_block(s_, zero, dims, zero, zero), PANOPTES_ERROR_USAGE);  // the blocks stay fixed
  ASSERT_EQ(panoptes_set_field_n(s_, "T", yin1.data(), PANOPTES_FLOAT64, nullptr, (long long)yin1.size()), PANOPTES_OK);
  ASSERT_EQ(panoptes_set_patch(s_, 1), PANOPTES_OK) << panoptes_last_error();
  ASSERT_EQ(panoptes_snapshot(s_, 1.0), PANOPTES_OK) << panoptes_last_error();
  ASSERT_EQ(panoptes_finalize(s_), PANOPTES_OK) << panoptes_last_error();
  const std::string m = manifest();
  const auto at = m.find("\"references\":[");
  ASSERT_NE(at, std::string::npos) << m.substr(0, 600);
  double r0 = 0, r1 = 0;
  ASSERT_EQ(std::sscanf(m.c_str() + at, "\"references\":[%lf,%lf", &r0, &r1), 2) << m.substr(at, 80);
  EXPECT_GT(r1, 1.5 * r0) << "Yin's new array did not reach the picture: references " << r0 << ", " << r1;
}

TEST_F(CapiGrid, BadGridsAndBlocksAreRefusedWithTheirReason) {
  const int dims[3] = {6, 16, 36};
  std::vector<double> r = r_;
  r[3] = r[2];
  EXPECT_EQ(panoptes_set_grid_spherical(s_, dims, r.data(), t_.data(), p_.data()), PANOPTES_ERROR_USAGE);
  EXPECT_NE(std::string(panoptes_last_error()).find("panoptes_set_grid_spherical: spherical grid: r coordinates are not strictly increasing: r[2] = 0.64, r[3] = 0.64"),
            std::string::npos)
      << panoptes_last_error();
  // A Yin-Yang patch narrower than π/2 in θ leaves a gap.
  std::vector<double> narrow(t_.begin() + 3, t_.end() - 3);
  const int narrow_dims[3] = {6, int(narrow.size()), 36};
  EXPECT_EQ(panoptes_set_grid_yinyang(s_, narrow_dims, r_.data(), narrow.data(), p_.data()), PANOPTES_ERROR_USAGE);
  EXPECT_NE(std::string(panoptes_last_error()).find("leave a gap"), std::string::npos) << panoptes_last_error();
  const int bad_dims[3] = {1, 16, 36};
  EXPECT_EQ(panoptes_set_grid_rectilinear(s_, bad_dims, r_.data(), t_.data(), p_.data()), PANOPTES_ERROR_USAGE);
  EXPECT_EQ(panoptes_set_grid_rectilinear(s_, dims, r_.data(), nullptr, p_.data()), PANOPTES_ERROR_USAGE);
  // Patches exist only on Yin-Yang grids.
  ASSERT_EQ(panoptes_set_grid_spherical(s_, dims, r_.data(), t_.data(), p_.data()), PANOPTES_OK);
  EXPECT_EQ(panoptes_set_patch(s_, 1), PANOPTES_ERROR_USAGE);
  EXPECT_NE(std::string(panoptes_last_error()).find("only a Yin-Yang grid has patches"), std::string::npos);
  EXPECT_EQ(panoptes_set_resample(s_, 1, 0.0), PANOPTES_ERROR_USAGE);
  EXPECT_EQ(panoptes_set_resample(s_, 64, NAN), PANOPTES_ERROR_USAGE);
  // A Yin-Yang grid with only Yin's block: the Yang patch is missing.
  ASSERT_EQ(panoptes_set_grid_yinyang(s_, dims, r_.data(), t_.data(), p_.data()), PANOPTES_OK);
  EXPECT_EQ(panoptes_set_patch(s_, 2), PANOPTES_ERROR_USAGE);
  const int zero[3] = {0, 0, 0};
  ASSERT_EQ(panoptes_set_block(s_, zero, dims, zero, zero), PANOPTES_OK);
  std::vector<float> v(6 * 16 * 36, 0.5f);
  ASSERT_EQ(panoptes_set_field_n(s_, "T", v.data(), PANOPTES_FLOAT32, nullptr, (long long)v.size()), PANOPTES_OK);
  EXPECT_EQ(panoptes_snapshot(s_, 0.0), PANOPTES_ERROR_RUN);
  EXPECT_NE(std::string(panoptes_last_error()).find("points of patch 1 of the yinyang 6x16x36"), std::string::npos)
      << panoptes_last_error();
  EXPECT_NE(std::string(panoptes_last_error()).find("a block is missing"), std::string::npos);
}

TEST_F(CapiGrid, OverlappingBlocksAreNamed) {
  const int dims[3] = {6, 16, 36}, zero[3] = {0, 0, 0};
  ASSERT_EQ(panoptes_set_grid_yinyang(s_, dims, r_.data(), t_.data(), p_.data()), PANOPTES_OK);
  std::vector<float> v(6 * 16 * 36, 0.5f);
  // Yin and Yang both described... as patch 0 twice is impossible through set_patch; a block larger
  // than the grid is refused instead, naming the block.
  const int big[3] = {6, 17, 36};
  ASSERT_EQ(panoptes_set_block(s_, zero, big, zero, zero), PANOPTES_OK);
  ASSERT_EQ(panoptes_set_patch(s_, 1), PANOPTES_OK);
  ASSERT_EQ(panoptes_set_block(s_, zero, dims, zero, zero), PANOPTES_OK);
  ASSERT_EQ(panoptes_set_field_n(s_, "T", v.data(), PANOPTES_FLOAT32, nullptr, (long long)v.size()), PANOPTES_OK);
  ASSERT_EQ(panoptes_set_patch(s_, 0), PANOPTES_OK);
  std::vector<float> w(6 * 17 * 36, 0.5f);
  ASSERT_EQ(panoptes_set_field_n(s_, "T", w.data(), PANOPTES_FLOAT32, nullptr, (long long)w.size()), PANOPTES_OK);
  EXPECT_EQ(panoptes_snapshot(s_, 0.0), PANOPTES_ERROR_RUN);
  EXPECT_NE(std::string(panoptes_last_error()).find("outside the grid's (6, 16, 36) points"), std::string::npos)
      << panoptes_last_error();
}

// The C++ header's grid calls reach the same checks (panoptes::Error with the C API's code and message).
TEST_F(CapiGrid, CppWrapperGridCalls) {
  panoptes::Session viz(config((dir_ / "cpp").string()), false);
  std::vector<double> r = r_;
  r[3] = r[2];
  try {
    viz.set_grid_spherical(r, t_, p_);
    FAIL() << "non-monotonic radii accepted";
  } catch (const panoptes::Error& e) {
    EXPECT_EQ(e.code(), PANOPTES_ERROR_USAGE);
    EXPECT_NE(std::string(e.what()).find("r coordinates are not strictly increasing"), std::string::npos) << e.what();
  }
  viz.set_grid_yinyang(r_, t_, p_);
  viz.set_patch(1);
  viz.set_resample(32, 0.0);
  EXPECT_THROW(viz.set_patch(3), panoptes::Error);
  viz.set_grid_rectilinear(r_, t_, p_);
  EXPECT_THROW(viz.set_patch(0), panoptes::Error);  // only Yin-Yang grids have patches
}

}  // namespace
