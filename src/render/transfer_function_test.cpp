#include "render/transfer_function.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"

using namespace panoptes;
using namespace panoptes::render;

TEST(TransferFunction, PiecewiseLinearInterpolation) {
  TransferFunction tf;
  tf.colour = {{0, {0, 0, 0}}, {0.5f, {1, 0, 0}}, {1, {1, 1, 0}}};
  tf.opacity = {{0.2f, 0}, {0.6f, 2}};
  EXPECT_FLOAT_EQ(tf.colour_at(0.25f).r, 0.5f);
  EXPECT_FLOAT_EQ(tf.colour_at(0.75f).g, 0.5f);
  EXPECT_FLOAT_EQ(tf.extinction_at(0.1f), 0);   // constant before the first point
  EXPECT_FLOAT_EQ(tf.extinction_at(0.4f), 1);
  EXPECT_FLOAT_EQ(tf.extinction_at(0.9f), 2);   // constant after the last point
}

TEST(TransferFunction, LutOpacityIsExactForTheStep) {
  const auto tf = TransferFunction::constant({1, 0.5f, 0}, 0.3f);
  for (double step : {0.25, 0.5, 1.0}) {
    TransferLut lut(tf, ValueWindow::absolute(0, 1), step);
    const LutEntry& e = lut(0.5f);
    EXPECT_NEAR(e.alpha, 1 - std::exp(-0.3 * step), 1e-6);
    EXPECT_NEAR(e.pg, 0.5 * e.alpha, 1e-6);
    EXPECT_NEAR(e.tau, 0.3 * step, 1e-6);
  }
}

TEST(TransferFunction, LutClampsOutsideTheWindowAndHandlesNaN) {
  TransferLut lut(TransferFunction::preset("grayscale"), ValueWindow::absolute(-2, 2), 1.0);
  EXPECT_EQ(lut.bin(-100), 0);
  EXPECT_EQ(lut.bin(100), lut.bins() - 1);
  EXPECT_EQ(lut.bin(std::nanf("")), 0);
  EXPECT_EQ(lut.bin(0), lut.bins() / 2);
}

TEST(TransferFunction, VisibilityOfValueRanges) {
  // p-wave: transparent below 10 % of the window, uses |v|.
  TransferLut lut(TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1), 0.5);
  EXPECT_FALSE(lut.visible(-0.05f, 0.05f));
  EXPECT_TRUE(lut.visible(0.0f, 0.5f));
  EXPECT_TRUE(lut.visible(-0.5f, -0.3f));  // absolute value
  EXPECT_TRUE(lut.visible(-0.3f, 0.02f));
  TransferLut div(TransferFunction::preset("diverging"), ValueWindow::absolute(-1, 1), 0.5);
  EXPECT_FALSE(div.visible(-0.05f, 0.05f));
  EXPECT_TRUE(div.visible(-0.9f, -0.8f));
  EXPECT_TRUE(div.visible(0.8f, 0.9f));
}

TEST(TransferFunction, PresetsAreValidAndUnknownNamesFail) {
  for (const auto& n : TransferFunction::preset_names()) EXPECT_NO_THROW(TransferFunction::preset(n).validate()) << n;
  try {
    TransferFunction::preset("plasma-x");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("p-wave"), std::string::npos);
  }
  TransferFunction bad;
  bad.opacity = {{0.5f, 1}, {0.2f, 1}};
  EXPECT_THROW(bad.validate(), Error);
}

TEST(ValueWindow, RelativeWindowsResolveAgainstTheReference) {
  const auto w = ValueWindow::relative_to(-0.5, 1.0).resolve(4.0);
  EXPECT_DOUBLE_EQ(w.lo, -2);
  EXPECT_DOUBLE_EQ(w.hi, 4);
  EXPECT_FALSE(w.relative);
  EXPECT_THROW(ValueWindow::relative_to(0, 1).resolve(0), Error);
  EXPECT_THROW(ValueWindow::absolute(1, 1).resolve(0), Error);
  EXPECT_THROW(TransferLut(TransferFunction{}, ValueWindow::relative_to(0, 1), 0.5), Error);
}

TEST(ValueWindow, PercentileAndRunningMax) {
  GridGeometry g{{10, 10, 10}, {0, 0, 0}, {1, 1, 1}};
  std::vector<float> v(1000);
  for (int i = 0; i < 1000; ++i) v[std::size_t(i)] = (i % 2 ? -1.0f : 1.0f) * float(i);  // |v| = 0 … 999
  const FieldView f = FieldView::whole(g, v.data());
  EXPECT_NEAR(abs_percentile(f, 0.5), 500, 2);
  EXPECT_NEAR(abs_percentile(f, 0.99), 989, 2);
  EXPECT_EQ(abs_max(f), 999);
  RunningMax rm;
  EXPECT_EQ(rm.update(3), 3);
  EXPECT_EQ(rm.update(2), 3);
  EXPECT_EQ(rm.update(NAN), 3);
  EXPECT_EQ(rm.update(5), 5);
}
