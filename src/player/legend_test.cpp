#include "player/legend.hpp"

#include <gtest/gtest.h>

using namespace panoptes;
using namespace panoptes::player;

namespace {

// A manifest as `panoptes run` writes it: phi_p in 1/s with per-frame references, a relative window on
// the p-wave preset's control points, and a two-field task.
store::Manifest seismic_like() {
  store::Manifest m;
  m.time_units = "s";
  m.fields = {{"phi_p", "1/s", {0.5, 2.0}, ""}, {"phi_s", "1/s", {4.0}, ""}};
  const nlohmann::json pwave = {{"colour", {{0, 0.9, 0.35, 0.05}, {1, 1.0, 0.8, 0.4}}},
                                {"extinction", {{0, 0}, {0.1, 0}, {1, 0.5}}},
                                {"absolute_value", true}};
  store::TaskEntry p;
  p.id = 0, p.name = "p-wave", p.method = "volume", p.fields = {"phi_p"};
  p.parameters = {{"window", {0.0, 1.0}}, {"relative", true}, {"transfer_function", pwave}};
  store::TaskEntry ps;
  ps.id = 1, ps.name = "p+s", ps.method = "volume", ps.fields = {"phi_p", "phi_s"};
  ps.parameters = {{"window", {0.0, 1.0}}, {"relative", true}, {"window2", {0.0, 0.5}}, {"relative2", true},
                   {"transfer_function", pwave}, {"transfer_function2", pwave}};
  store::TaskEntry iso;
  iso.id = 2, iso.name = "iso", iso.method = "isosurface", iso.fields = {"phi_s"};
  iso.parameters = {{"isovalue", 0.25}, {"relative", true}, {"colour", {0.2, 0.4, 0.6}}};
  store::TaskEntry synthetic;
  synthetic.id = 3, synthetic.name = "synthetic", synthetic.method = "synthetic", synthetic.fields = {"x"};
  m.tasks = {p, ps, iso, synthetic};
  return m;
}

}  // namespace

TEST(Legend, RelativeWindowsFollowTheFramesReference) {
  const store::Manifest m = seismic_like();
  auto bars = task_legend(m, 0, 0);
  ASSERT_EQ(bars.size(), 1u);
  EXPECT_EQ(bars[0].label, "|phi_p|");
  EXPECT_EQ(bars[0].units, "1/s");
  EXPECT_TRUE(bars[0].physical);
  EXPECT_DOUBLE_EQ(bars[0].hi, 0.5);
  EXPECT_DOUBLE_EQ(task_legend(m, 0, 1)[0].hi, 2.0);
  EXPECT_DOUBLE_EQ(task_legend(m, 0, 7)[0].hi, 2.0) << "frames past the recorded ones keep the last reference";
  EXPECT_EQ(legend_range_text(bars[0]), "0 .. 0.5 1/s");
  // Colours: black (transparent) below 10 % of the window, the preset's orange brightening above.
  ASSERT_EQ(bars[0].colours.size(), std::size_t(kLegendSamples));
  EXPECT_EQ(bars[0].colours[0], (std::array<float, 3>{0, 0, 0}));
  const auto& top = bars[0].colours.back();
  const float alpha = float(1 - std::exp(-0.5 * kLegendDepthVoxels));
  EXPECT_NEAR(top[0], 1.0f * alpha, 1e-6);
  EXPECT_NEAR(top[1], 0.8f * alpha, 1e-6);
  EXPECT_GT(top[0], top[2]);
}

TEST(Legend, TwoFieldsIsovaluesAndTasksWithoutWindows) {
  const store::Manifest m = seismic_like();
  const auto ps = task_legend(m, 1, 0);
  ASSERT_EQ(ps.size(), 2u);
  EXPECT_EQ(ps[1].field, "phi_s");
  EXPECT_DOUBLE_EQ(ps[1].hi, 2.0);  // 0.5 x phi_s's 4.0
  const auto iso = task_legend(m, 2, 0);
  ASSERT_EQ(iso.size(), 1u);
  EXPECT_TRUE(iso[0].isovalue);
  EXPECT_DOUBLE_EQ(iso[0].lo, 1.0);
  EXPECT_EQ(legend_range_text(iso[0]), "iso 1 1/s");
  ASSERT_EQ(iso[0].colours.size(), 1u);
  EXPECT_FLOAT_EQ(iso[0].colours[0][2], 0.6f);
  EXPECT_TRUE(task_legend(m, 3, 0).empty());
  EXPECT_TRUE(task_legend(m, 99, 0).empty());
}

TEST(Legend, OlderManifestsShowFractionsOfTheReference) {
  store::Manifest m = seismic_like();
  m.fields.clear();
  m.time_units.clear();
  m.tasks[0].parameters.erase("transfer_function");
  const auto bars = task_legend(m, 0, 0);
  ASSERT_EQ(bars.size(), 1u);
  EXPECT_FALSE(bars[0].physical);
  EXPECT_TRUE(bars[0].colours.empty());
  EXPECT_EQ(bars[0].label, "phi_p");
  EXPECT_EQ(legend_range_text(bars[0]), "0 .. 1 x reference");
  EXPECT_EQ(time_text(m, 4.25), "t = 4.25");
  m.time_units = "s";
  EXPECT_EQ(time_text(m, 4.25), "t = 4.25 s");
  // Malformed parameters are left out, never thrown.
  m.tasks[0].parameters["transfer_function"] = {{"colour", "red"}, {"extinction", {{0, 1}}}};
  EXPECT_TRUE(task_legend(m, 0, 0)[0].colours.empty());
}

TEST(Legend, Numbers) {
  EXPECT_EQ(legend_number(0), "0");
  EXPECT_EQ(legend_number(0.015), "0.015");
  EXPECT_EQ(legend_number(120), "120");
  EXPECT_EQ(legend_number(2.4123e-4), "2.41e-04");
  EXPECT_EQ(legend_number(3e6), "3.00e+06");
}

// Issue 41: the legend says what the scale follows and, when the reference changed since the previous
// frame, by what factor; a shared two-field scale uses the larger reference of the two fields.
TEST(Legend, ScaleModeChangeAndSharedReference) {
  store::Manifest m = seismic_like();
  m.fields[0].reference_mode = "snapshot";
  m.fields[1].references = {4.0, 4.0};
  m.fields[1].reference_mode = "running";
  auto p0 = task_legend(m, 0, 0)[0];
  EXPECT_EQ(p0.scale, "snapshot");
  EXPECT_EQ(legend_scale_text(p0), "per snapshot");
  const auto p1 = task_legend(m, 0, 1)[0];
  EXPECT_DOUBLE_EQ(p1.change, 4.0);
  EXPECT_EQ(legend_scale_text(p1), "per snapshot: x4 since the previous frame");
  // Shared: both bars of p+s multiply max(phi_p, phi_s) = 4 at frame 0.
  m.tasks[1].parameters["scale"] = "shared";
  const auto ps = task_legend(m, 1, 0);
  ASSERT_EQ(ps.size(), 2u);
  EXPECT_TRUE(ps[0].shared);
  EXPECT_DOUBLE_EQ(ps[0].hi, 4.0);
  EXPECT_DOUBLE_EQ(ps[1].hi, 2.0);  // window2 [0, 0.5] of the shared 4
  EXPECT_EQ(legend_scale_text(ps[1], "phi_p"), "running max, shared with phi_p");
  EXPECT_DOUBLE_EQ(task_legend(m, 1, 1)[0].change, 1.0);  // max(2, 4) = max(0.5, 4): no change
  // Own scales: each its own reference.
  m.tasks[1].parameters["scale"] = "own";
  EXPECT_DOUBLE_EQ(task_legend(m, 1, 0)[0].hi, 0.5);
  // Older manifests: no mode recorded; a running-maximum note means "running", else per snapshot.
  m.fields[0].reference_mode.clear();
  EXPECT_EQ(task_legend(m, 0, 0)[0].scale, "snapshot");
  m.provenance.extra["insitu.running_max"] = "0.5 4";
  EXPECT_EQ(task_legend(m, 0, 0)[0].scale, "running");
  // Absolute windows have no scale to name.
  m.tasks[0].parameters["relative"] = false;
  EXPECT_EQ(legend_scale_text(task_legend(m, 0, 0)[0]), "");
}

// Fixed scales (examples/paper.toml: reference = "fixed", one value in every frame): the legend gives
// the window times that value in the field's unit, names the scale "fixed" and never a change.
TEST(Legend, FixedScalesShowTheConfiguredValueInEveryFrame) {
  store::Manifest m = seismic_like();
  m.fields[0].references = {5e-5, 5e-5, 5e-5};
  m.fields[0].reference_mode = "fixed";
  m.fields[1].references = {1.5e-4, 1.5e-4, 1.5e-4};
  m.fields[1].reference_mode = "fixed";
  m.provenance.extra["insitu.running_max"] = "0 0";  // as the paper run records it: the mode wins
  for (int frame = 0; frame < 4; ++frame) {  // frame 3: past the recorded ones, the last reference
    const auto p = task_legend(m, 0, frame);
    ASSERT_EQ(p.size(), 1u);
    EXPECT_TRUE(p[0].physical);
    EXPECT_EQ(p[0].scale, "fixed");
    EXPECT_DOUBLE_EQ(p[0].hi, 5e-5);
    EXPECT_EQ(legend_range_text(p[0]), "0 .. 5.00e-05 1/s");
    EXPECT_EQ(legend_scale_text(p[0]), "fixed") << "frame " << frame;
    EXPECT_EQ(legend_change_text(p[0]), "");
  }
  // p+s on the shared scale: both windows multiply the larger value, phi_s's 1.5e-4.
  m.tasks[1].parameters["scale"] = "shared";
  m.tasks[1].parameters["window"] = {0.0, 0.33};
  m.tasks[1].parameters["window2"] = {0.0, 1.0};
  const auto ps = task_legend(m, 1, 2);
  ASSERT_EQ(ps.size(), 2u);
  EXPECT_EQ(legend_range_text(ps[0]), "0 .. 4.95e-05 1/s");
  EXPECT_EQ(legend_range_text(ps[1]), "0 .. 1.50e-04 1/s");
  EXPECT_EQ(legend_scale_text(ps[0], "phi_s"), "fixed, shared with phi_s");
  EXPECT_EQ(legend_scale_text(ps[1], "phi_p"), "fixed, shared with phi_p");
}

// Issue 41.4: a slice is drawn opaque (render/march_plan.cpp: slice_opacity 1, the colour map's colour
// as it is), so its legend shows the colour map itself. Drawn as a volume's thin layer over black, the
// diverging preset's zero — light grey (222, 222, 222) on the plane — was black in the legend.
TEST(Legend, ASlicesColoursAreItsColourMapAsTheSliceIsDrawn) {
  store::Manifest m;
  m.fields = {{"vz", "m/s", {2.0}, ""}};
  const nlohmann::json diverging = {{"colour", {{0, 0.23, 0.30, 0.75}, {0.5, 0.87, 0.87, 0.87}, {1, 0.71, 0.02, 0.15}}},
                                    {"extinction", {{0, 0.5}, {0.45, 0}, {0.55, 0}, {1, 0.5}}},
                                    {"absolute_value", false}};
  store::TaskEntry slice;
  slice.id = 0, slice.name = "slice", slice.method = "slice", slice.fields = {"vz"};
  slice.parameters = {{"axis", "z"}, {"position", 0.5}, {"window", {-1.0, 1.0}}, {"relative", true},
                      {"transfer_function", diverging}};
  store::TaskEntry volume = slice;
  volume.id = 1, volume.name = "volume", volume.method = "volume";
  m.tasks = {slice, volume};
  const auto s = task_legend(m, 0, 0);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_DOUBLE_EQ(s[0].lo, -2.0);
  ASSERT_EQ(s[0].colours.size(), std::size_t(kLegendSamples));
  // kLegendSamples = 32 values from lo to hi: zero lies between samples 15 and 16, each 1/62 of the
  // window from it; the grey there is within 2 levels of 222.
  for (const int i : {15, 16})
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[0].colours[std::size_t(i)][k] * 255, 222, 10) << "sample " << i;
  EXPECT_NEAR(s[0].colours[0][2], 0.75f, 1e-6) << "the map's low end, unattenuated";
  EXPECT_NEAR(s[0].colours.back()[0], 0.71f, 1e-6);
  // The same map on a volume stays a thin layer over black: transparent values are dark.
  const auto v = task_legend(m, 1, 0);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_LT(v[0].colours[16][0], 0.05f);
  // A slice recorded as translucent is drawn at that opacity over black.
  m.tasks[0].parameters["slice_opacity"] = 0.5;
  EXPECT_NEAR(task_legend(m, 0, 0)[0].colours[0][2], 0.375f, 1e-6);
}

// Issue 43: a maximum-intensity projection is opaque like a slice (the renderer writes the colour
// map's colour at each ray's maximum with alpha 1), so its legend is the colour map over its window.
TEST(Legend, AMipsColoursAreItsColourMapOpaque) {
  store::Manifest m;
  m.fields = {{"p", "1/s", {4.0}, ""}};
  const nlohmann::json hot = {{"colour", {{0, 0.0, 0.0, 0.0}, {0.5, 1.0, 0.4, 0.0}, {1, 1.0, 1.0, 1.0}}},
                              {"extinction", {{0, 0.0}, {1, 0.2}}},
                              {"absolute_value", true}};
  store::TaskEntry mip;
  mip.id = 0, mip.name = "mip", mip.method = "mip", mip.fields = {"p"};
  mip.parameters = {{"preset", "hot"}, {"window", {0.0, 0.5}}, {"relative", true}, {"transfer_function", hot}};
  m.tasks = {mip};
  const auto b = task_legend(m, 0, 0);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_DOUBLE_EQ(b[0].hi, 2.0);  // 0.5 x the reference 4
  EXPECT_EQ(b[0].label, "|p|");
  ASSERT_EQ(b[0].colours.size(), std::size_t(kLegendSamples));
  EXPECT_NEAR(b[0].colours.back()[2], 1.0f, 1e-6) << "the map's top, unattenuated (a volume's layer would be dim)";
  const int mid = (kLegendSamples - 1) / 2;  // u = 15/31: 30/31 of the way to the map's middle point
  EXPECT_NEAR(b[0].colours[std::size_t(mid)][0], 30.0f / 31, 1e-5);
  EXPECT_NEAR(b[0].colours[std::size_t(mid)][1], 0.4f * 30 / 31, 1e-5);
}
