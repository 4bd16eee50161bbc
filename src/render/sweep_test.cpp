// render_sweep(): a sweep's frames against each task rendered alone by render_brick().
#include "render/sweep.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "render/render_test_util.hpp"
#include "render/synthetic_fields.hpp"

namespace panoptes::render {
namespace {

// The dense scene on a small grid (sharp fronts and standing waves, values of both signs).
struct SmallScene {
  GridGeometry grid{{48, 64, 40}, {0, 0, 0}, {1, 1, 1}};
  DenseWaveScene waves = dense_wave_scene(grid);
  FieldView view = FieldView::whole(grid, waves.p.data());
  double ref = abs_percentile(view, 0.999);
  camera::Camera cam{grid.centre() + Vec3{90, -70, 50}, grid.centre(), {0, 0, 1}, 40, 96, 80};
};

// Task t's sweep frame and its image alone, both finished over the same background.
void frames_against_alone(const SmallScene& s, const std::vector<PreparedField>& fields,
                          const std::vector<TaskSpec>& tasks, double min_db, int max_channel_error) {
  SweepFrames frames;
  render_sweep(s.cam, fields, tasks, frames);
  ASSERT_EQ(frames.count, int(tasks.size()));
  PartialImage part;
  std::vector<PartialImage> one(1);
  int shown = 0;
  for (std::size_t t = 0; t < tasks.size(); ++t) {
    render_brick(s.cam, fields, std::span(tasks).subspan(t, 1), one);
    const Image alone = finish_image(one[0], s.cam, s.grid, {0.1f, 0.1f, 0.15f});
    frames.to_partial(int(t), part);
    const Image swept = finish_image(part, s.cam, s.grid, {0.1f, 0.1f, 0.15f});
    EXPECT_GE(std::min(99.0, psnr(swept, alone)), min_db) << "task " << t;
    EXPECT_LE(testing::max_diff(swept, alone), max_channel_error) << "task " << t;
    for (float a : one[0].rgba) shown += a > 0;
  }
  EXPECT_GT(shown, 0);  // the tasks show something
}

TEST(Sweep, IsovaluesMatchEachIsosurfaceAlone) {
  const SmallScene s;
  std::vector<TaskSpec> tasks;
  // Unsorted and with a repeated value: frames follow the tasks, not the order of their isovalues.
  for (double f : {0.3, -0.5, 0.05, 0.7, -0.05, 0.3, -0.85})
    tasks.push_back(TaskSpec::isosurface(0, float(f * s.ref), {0.9f, 0.6f, 0.3f}));
  const std::vector<PreparedField> fields{PreparedField(s.view, MacroCells::kDefaultSize, FieldCopy::none)};
  // Hits are placed as render_brick() places them; their gradient comes from a spline through the
  // samples' gradients: measured 57 dB and more on sweep_bench's scene.
  frames_against_alone(s, fields, tasks, 45, 64);
}

TEST(Sweep, ManyIsovaluesPerSegmentMatchEachIsosurfaceAlone) {
  // 300 isovalues: a segment between two samples crosses several (up to dozens at the fronts), so
  // their regula-falsi step takes the field from the segment's cubic, not from an interpolation per hit.
  const SmallScene s;
  std::vector<TaskSpec> tasks;
  for (int j = 0; j < 300; ++j) tasks.push_back(TaskSpec::isosurface(0, float((-0.9 + 1.8 * j / 299) * s.ref)));
  const std::vector<PreparedField> fields{PreparedField(s.view, MacroCells::kDefaultSize, FieldCopy::none)};
  frames_against_alone(s, fields, tasks, 45, 64);
}

TEST(Sweep, WindowsMatchEachVolumeTaskAlone) {
  const SmallScene s;
  std::vector<TaskSpec> tasks;
  for (double lo : {0.0, 0.1, 0.3, 0.5})
    tasks.push_back(TaskSpec::volume(0, TransferFunction::preset("hot"), ValueWindow::relative_to(lo, lo + 0.25), s.ref));
  tasks.push_back(TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::relative_to(0, 0.6), s.ref));
  const std::vector<PreparedField> fields{PreparedField(s.view)};
  // The operations of render_brick()'s march per window: only the 8-bit storage differs (≤ 1/255).
  frames_against_alone(s, fields, tasks, 50, 1);
}

TEST(Sweep, WhatIsASweep) {
  const TransferFunction hot = TransferFunction::preset("hot");
  const TaskSpec iso = TaskSpec::isosurface(0, 0.5f), vol = TaskSpec::volume(0, hot, ValueWindow::absolute(0, 1));
  EXPECT_TRUE(is_sweep(std::vector{iso, TaskSpec::isosurface(0, 0.2f)}));
  EXPECT_TRUE(is_sweep(std::vector{vol, vol}));
  EXPECT_FALSE(is_sweep(std::vector{iso}));                                      // one task
  EXPECT_FALSE(is_sweep(std::vector{iso, vol}));                                 // two kinds
  EXPECT_FALSE(is_sweep(std::vector{iso, TaskSpec::isosurface(1, 0.2f)}));       // two fields
  EXPECT_FALSE(is_sweep(std::vector{TaskSpec::volume2(0, hot, {}, 1, hot, {}), vol}));  // two-field volume
}

TEST(Sweep, RefusesABrickThatIsNotTheDomain) {
  const SmallScene s;
  const std::vector<PreparedField> fields{PreparedField(s.view.subview(Brick::slab(s.grid, 2, 2, 0)))};
  const std::vector<TaskSpec> tasks{TaskSpec::isosurface(0, 0.1f), TaskSpec::isosurface(0, 0.2f)};
  SweepFrames frames;
  try {
    render_sweep(s.cam, fields, tasks, frames);
    FAIL() << "a half-domain brick was rendered";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("whole domain"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace panoptes::render
