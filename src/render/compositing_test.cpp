// Bricks composite to the single-brick image; one march for K tasks equals K marches; skipping
// does not change images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include "core/error.hpp"
#include "render/render_test_util.hpp"
#include "render/synthetic_fields.hpp"

using namespace panoptes;
using namespace panoptes::render;
using panoptes::render::testing::max_diff;
using panoptes::render::testing::render_bricked;

namespace {

struct Scene {
  GridGeometry grid{{41, 37, 33}, {-20, -21.6, -12.8}, {1.0, 1.2, 0.8}};
  std::vector<float> p, s;
  std::vector<FieldView> views;
  std::vector<TaskSpec> tasks;
  Scene() {
    const WaveFront pf[] = {{{-4, 3, 1}, 14, 2.5, 1.0}, {{6, -5, -2}, 8, 2, -0.8}};
    const WaveFront sf[] = {{{-4, 3, 1}, 8, 2, 0.9}};
    p = wave_field(grid, pf);
    s = wave_field(grid, sf);
    views = {FieldView::whole(grid, p.data()), FieldView::whole(grid, s.data())};
    // Every kind's examples, in the order of kTaskKinds: a kind added to the enum is tested by every
    // test below that loops over `tasks` the day it is added (and fails here until it has examples).
    for (const TaskKind k : kTaskKinds) {
      const std::vector<TaskSpec> ex = examples(k);
      if (ex.empty()) ADD_FAILURE() << "no compositing example for task kind " << to_string(k);
      tasks.insert(tasks.end(), ex.begin(), ex.end());
    }
  }
  // Two or three tasks of each kind on the two fields (indices 0-6 are used by name below).
  static std::vector<TaskSpec> examples(TaskKind k) {
    switch (k) {
      case TaskKind::volume:
        return {TaskSpec::volume(0, TransferFunction::preset("p-wave", 2), ValueWindow::absolute(0, 1)),
                TaskSpec::volume2(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1), 1,
                                  TransferFunction::preset("s-wave"), ValueWindow::relative_to(0, 1.0), 1.0, 0.9),
                TaskSpec::volume(0, TransferFunction::preset("diverging", 3), ValueWindow::absolute(-1, 1))};
      case TaskKind::isosurface:
        return {TaskSpec::isosurface(0, 0.4f, {1, 0.6f, 0.2f}), TaskSpec::isosurface(1, -0.2f, {0.3f, 0.9f, 0.4f})};
      case TaskKind::slice:
        return {TaskSpec::slice(0, 2, 1.3, TransferFunction::preset("diverging"), ValueWindow::absolute(-1, 1)),
                TaskSpec::slice(1, 0, -3.7, TransferFunction::preset("rainbow"), ValueWindow::absolute(-1, 1))};
      case TaskKind::mip:  // |p| on an absolute-value map; signed s on a diverging one
        return {TaskSpec::mip(0, TransferFunction::preset("hot"), ValueWindow::absolute(0.1, 0.9)),
                TaskSpec::mip(1, TransferFunction::preset("diverging"), ValueWindow::absolute(-1, 1))};
    }
    return {};
  }
  std::vector<Brick> slabs(int axis, int n) const {
    std::vector<Brick> b;
    for (int i = 0; i < n; ++i) b.push_back(Brick::slab(grid, axis, n, i));
    return b;
  }
};

const camera::Camera kCams[] = {
    camera::Camera({45, -60, 30}, {0, 0, 0}, {0, 0, 1}, 40, 64, 60),
    camera::Camera({-10, 8, -70}, {1, -1, 0}, {0, 1, 0}, 45, 60, 64),
    camera::Camera({-80, 5, 3}, {0, 0, 0}, {0, 0, 1}, 35, 64, 64),
};

}  // namespace

TEST(Compositing, BricksAlongZAndXMatchTheSingleBrickImage) {
  const Scene sc;
  for (const auto& cam : kCams) {
    const auto ref = render_bricked(cam, sc.views, sc.tasks, {Brick::whole(sc.grid)});
    for (int axis : {2, 0})
      for (int n : {2, 3, 4}) {
        const auto img = render_bricked(cam, sc.views, sc.tasks, sc.slabs(axis, n));
        for (std::size_t t = 0; t < sc.tasks.size(); ++t)
          EXPECT_LE(max_diff(img[t], ref[t]), 1) << "axis " << axis << ", " << n << " bricks, task " << t;
      }
  }
}

TEST(Compositing, BlockDecompositionInVisibilityOrderMatches) {
  const Scene sc;
  std::vector<Brick> blocks;  // 2 × 2 × 2 blocks of unequal size
  const int cx[] = {0, 17, 40}, cy[] = {0, 20, 36}, cz[] = {0, 11, 32};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) blocks.push_back({{cx[i], cy[j], cz[k]}, {cx[i + 1], cy[j + 1], cz[k + 1]}});
  for (const auto& cam : kCams) {
    const auto ref = render_bricked(cam, sc.views, sc.tasks, {Brick::whole(sc.grid)});
    const auto by_depth = render_bricked(cam, sc.views, sc.tasks, blocks);
    const auto ordered = render_bricked(cam, sc.views, sc.tasks, blocks, {}, true);
    for (std::size_t t = 0; t < sc.tasks.size(); ++t) {
      EXPECT_LE(max_diff(by_depth[t], ref[t]), 1) << "task " << t;
      EXPECT_LE(max_diff(ordered[t], ref[t]), 1) << "task " << t;
    }
  }
}

TEST(Compositing, OneMarchForKTasksEqualsKMarches) {
  const Scene sc;
  const auto& cam = kCams[0];
  std::vector<PreparedField> fields{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  std::vector<PartialImage> together(sc.tasks.size());
  const RenderStats st = render_brick(cam, fields, sc.tasks, together);
  std::uint64_t separate_marched = 0;
  for (std::size_t t = 0; t < sc.tasks.size(); ++t) {
    std::vector<PartialImage> one(1);
    separate_marched += render_brick(cam, fields, std::span(&sc.tasks[t], 1), one).marched_samples;
    EXPECT_EQ(one[0].rgba, together[t].rgba) << "task " << t;
  }
  EXPECT_LT(st.marched_samples, separate_marched);
}

// An isosurface sweep (many isovalues of one field, the case `BM_ManyImages/mix:2` measures): every
// isovalue's image from one march is its one-task image, bit for bit, with more than 8 values on one
// field, sweeps on two fields, a value repeated, values that are exactly grid values, and a volume
// task in the same march. Guards any per-block shortcut over the live isovalues (one was tried in
// Round 8 of docs/rendering.md; this test caught its off-by-one mutant).
TEST(Compositing, IsosurfaceSweepInOneMarchGivesEveryIsovalueItsOneTaskImage) {
  const Scene sc;
  std::vector<PreparedField> fields{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  std::vector<TaskSpec> tasks;
  for (int i = 0; i < 11; ++i)
    tasks.push_back(TaskSpec::isosurface(0, -0.75f + 0.15f * float(i), {1, 0.1f * float(i), 0.2f}));
  tasks.push_back(TaskSpec::isosurface(0, 0.3f, {0.2f, 0.2f, 1}));  // the same value as task 7
  tasks.push_back(TaskSpec::isosurface(0, sc.p[std::size_t(20 + 41 * (18 + 37 * 16))], {0.5f, 1, 0.5f}));
  tasks.push_back(TaskSpec::isosurface(0, sc.p[std::size_t(23 + 41 * (20 + 37 * 17))], {0.5f, 0.5f, 1}));
  for (int i = 0; i < 4; ++i)
    tasks.push_back(TaskSpec::isosurface(1, -0.3f + 0.2f * float(i), {0.3f, 0.9f, 0.1f * float(i)}));
  tasks.push_back(sc.tasks[0]);
  for (const auto& cam : kCams) {
    std::vector<PartialImage> together(tasks.size());
    const RenderStats st = render_brick(cam, fields, tasks, together);
    std::uint64_t separate_marched = 0;
    int with_hits = 0;
    for (std::size_t t = 0; t < tasks.size(); ++t) {
      std::vector<PartialImage> one(1);
      separate_marched += render_brick(cam, fields, std::span(&tasks[t], 1), one).marched_samples;
      EXPECT_EQ(one[0].rgba, together[t].rgba) << "task " << t;
      bool hit = false;
      for (std::size_t i = 3; i < one[0].rgba.size() && !hit; i += 4) hit = one[0].rgba[i] > 0;
      with_hits += hit;
    }
    EXPECT_GE(with_hits, 12);  // the scene gives most isovalues a surface to hit
    EXPECT_LT(st.marched_samples, separate_marched);
  }
}

// The paper's three volume tasks on the test scene: p, s and the two-field p+s.
std::vector<TaskSpec> p_s_and_ps_tasks() {
  return {
      TaskSpec::volume(0, TransferFunction::preset("p-wave", 2), ValueWindow::absolute(0, 1)),
      TaskSpec::volume(1, TransferFunction::preset("s-wave", 2), ValueWindow::absolute(0, 0.9)),
      TaskSpec::volume2(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1), 1,
                        TransferFunction::preset("s-wave"), ValueWindow::absolute(0, 0.9)),
  };
}

// Volume tasks on p and s: in one march both fields' corner copies are read with one shared
// geometry (interp_block_corners_n<2>), alone with their own; a field without a corner copy (gathered
// floats) must not be paired. Every task's image must be its one-task image, bit for bit.
// A transfer-function sweep (windows of one field, the case `BM_ManyImages/mix:1` measures) takes
// march_volumes() and runs over macro-cells whose visible windows differ: each window sees other
// cells (low, middle, high values), so the runs go on for the union and every window composites exact
// no-ops where it sees nothing. Every image must be its one-task image, bit for bit, for 2 … 12
// windows (the loop) and 14 (the general path), with opaque windows dropping out on the way.
TEST(Compositing, TransferFunctionSweepInOneMarchGivesEveryWindowItsOneTaskImage) {
  const Scene sc;
  std::vector<PreparedField> fields{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  std::vector<TaskSpec> all;
  for (int i = 0; i < 14; ++i) {
    const float lo = -0.9f + 0.13f * float(i);
    all.push_back(TaskSpec::volume(0, TransferFunction::preset(i % 2 ? "hot" : "p-wave", 1 + i % 3),
                                   ValueWindow::absolute(lo, lo + 0.25f + 0.1f * float(i % 4))));
  }
  int opaque = 0;
  for (const std::size_t k : {std::size_t(2), std::size_t(5), std::size_t(12), std::size_t(14)}) {
    const std::span<const TaskSpec> tasks(all.data(), k);
    for (const auto& cam : kCams) {
      std::vector<PartialImage> together(k);
      render_brick(cam, fields, tasks, together);
      for (std::size_t t = 0; t < k; ++t) {
        std::vector<PartialImage> one(1);
        render_brick(cam, fields, tasks.subspan(t, 1), one);
        EXPECT_EQ(one[0].rgba, together[t].rgba) << k << " windows, window " << t;
        for (std::size_t i = 3; i < one[0].rgba.size(); i += 4) opaque += one[0].rgba[i] > 0.98f;
      }
    }
  }
  EXPECT_GT(opaque, 100);  // rays that terminate: windows leave the loop while others go on
}

TEST(Compositing, FieldsReadWithOneSharedGeometryGiveTheirOneFieldImages) {
  const Scene sc;
  const std::vector<TaskSpec> tasks = p_s_and_ps_tasks();
  for (const FieldCopy s_copy : {FieldCopy::corners16, FieldCopy::none}) {
    std::vector<PreparedField> fields{PreparedField(sc.views[0]),
                                      PreparedField(sc.views[1], MacroCells::kDefaultSize, s_copy)};
    ASSERT_FALSE(fields[0].corners.empty());
    for (const auto& cam : kCams) {
      std::vector<PartialImage> together(tasks.size());
      render_brick(cam, fields, tasks, together);
      for (std::size_t t = 0; t < tasks.size(); ++t) {
        std::vector<PartialImage> one(1);
        render_brick(cam, fields, std::span(&tasks[t], 1), one);
        EXPECT_EQ(one[0].rgba, together[t].rgba) << "task " << t << ", s corner copy " << (s_copy == FieldCopy::corners16);
      }
      float peak = 0;  // the scene must give the tasks something to composite
      for (float a : together[2].rgba) peak = std::max(peak, a);
      EXPECT_GT(peak, 0.1f);
    }
  }
}

// The paper's mix (p, s, p+s) runs in its own loop while exactly those three tasks are live
// (march_trio()): in any task order, on a joint copy, and taking over mid-ray when an isosurface
// task that was marched with them has found its hit, every image is its one-task image, bit for bit.
TEST(Compositing, ThePaperMixInItsOwnLoopGivesTheOneTaskImagesInAnyOrder) {
  const Scene sc;
  const std::vector<TaskSpec> pss = p_s_and_ps_tasks();
  const std::vector<PreparedField> separate{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  const std::vector<std::vector<TaskSpec>> mixes{
      {pss[2], pss[1], pss[0]},
      {pss[1], pss[2], pss[0]},
      {pss[0], sc.tasks[3], pss[1], pss[2]},  // an isosurface of p: the trio takes over after its hit
  };
  for (const std::vector<TaskSpec>& tasks : mixes) {
    const std::vector<PreparedField> joint = prepare_fields(sc.views, tasks);
    ASSERT_EQ(joint[1].corners.data(), joint[0].corners.data() + 8);
    for (const auto& cam : kCams) {
      std::vector<PartialImage> together(tasks.size());
      render_brick(cam, joint, tasks, together);
      for (std::size_t t = 0; t < tasks.size(); ++t) {
        std::vector<PartialImage> one(1);
        render_brick(cam, separate, std::span(&tasks[t], 1), one);
        EXPECT_EQ(one[0].rgba, together[t].rgba) << "task " << t << " of " << tasks.size();
      }
    }
  }
}

// prepare_fields() gives the fields that volume tasks read together one interleaved corner copy
// (Round 9 of docs/rendering.md), and the march composites single-field volume tasks in groups of
// four with their chains interleaved. Neither may change a bit: with p, s and p+s, six more volume
// tasks on p (two groups, one of them partial), isosurfaces and slices in one march, every task's
// image equals its one-task image on separately prepared fields, on bricks too (the joint copy of a
// brick view), and a single task read from the joint copy equals its own copy's image.
TEST(Compositing, JointCornerCopiesAndGroupedTasksGiveTheOneTaskImages) {
  const Scene sc;
  std::vector<TaskSpec> tasks = p_s_and_ps_tasks();
  for (int i = 0; i < 6; ++i)
    tasks.push_back(TaskSpec::volume(0, TransferFunction::preset(i % 2 ? "hot" : "p-wave", 1 + i % 3),
                                     ValueWindow::absolute(0, 0.5 + 0.15 * i)));
  tasks.push_back(TaskSpec::volume(1, TransferFunction::preset("diverging", 3), ValueWindow::absolute(-1, 1)));
  tasks.push_back(sc.tasks[3]);  // isosurfaces and slices of both fields
  tasks.push_back(sc.tasks[4]);
  tasks.push_back(sc.tasks[5]);
  tasks.push_back(sc.tasks[6]);
  const std::vector<PreparedField> joint = prepare_fields(sc.views, tasks);
  ASSERT_EQ(joint.size(), 2u);
  ASSERT_EQ(joint[0].corners.record(), 16);
  ASSERT_EQ(joint[1].corners.data(), joint[0].corners.data() + 8);
  const std::vector<PreparedField> separate{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  ASSERT_EQ(separate[0].corners.record(), 8);
  for (const auto& cam : kCams) {
    std::vector<PartialImage> together(tasks.size());
    render_brick(cam, joint, tasks, together);
    for (std::size_t t = 0; t < tasks.size(); ++t) {
      std::vector<PartialImage> one(1), one_joint(1);
      render_brick(cam, separate, std::span(&tasks[t], 1), one);
      EXPECT_EQ(one[0].rgba, together[t].rgba) << "task " << t;
      render_brick(cam, joint, std::span(&tasks[t], 1), one_joint);
      EXPECT_EQ(one[0].rgba, one_joint[0].rgba) << "task " << t;
    }
  }
  // Bricks: each brick's fields prepared jointly still composite to the single-brick image.
  const auto& cam = kCams[1];
  std::vector<PartialImage> whole(3);
  render_brick(cam, separate, std::span(tasks.data(), 3), whole);
  for (const Brick& b : sc.slabs(2, 3)) {
    const std::vector<FieldView> v{sc.views[0].subview(b), sc.views[1].subview(b)};
    const std::vector<PreparedField> jb = prepare_fields(v, std::span(tasks.data(), 3));
    const std::vector<PreparedField> sb{PreparedField(v[0]), PreparedField(v[1])};
    std::vector<PartialImage> pj(3), ps(3);
    render_brick(cam, jb, std::span(tasks.data(), 3), pj);
    render_brick(cam, sb, std::span(tasks.data(), 3), ps);
    for (int t = 0; t < 3; ++t) EXPECT_EQ(pj[std::size_t(t)].rgba, ps[std::size_t(t)].rgba) << "task " << t;
  }
}

// Which copies prepare_fields() builds: none for a field only isosurfaces or slices read, its own
// for a volume field without a partner, joint ones for two volume fields; bad field indices throw.
TEST(Compositing, PrepareFieldsBuildsTheCopiesTheTasksRead) {
  const Scene sc;
  const TaskSpec vol_p = TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1));
  const TaskSpec iso_s = TaskSpec::isosurface(1, 0.2f);
  const std::vector<TaskSpec> p_and_iso{vol_p, iso_s};
  std::vector<PreparedField> f = prepare_fields(sc.views, p_and_iso);
  EXPECT_EQ(f[0].corners.record(), 8);
  EXPECT_FALSE(f[0].corners.empty());
  EXPECT_TRUE(f[1].corners.empty());
  EXPECT_EQ(f[1].view.data, sc.views[1].data);
  f = prepare_fields(sc.views, p_s_and_ps_tasks());
  EXPECT_EQ(f[0].corners.record(), 16);
  EXPECT_EQ(f[1].corners.record(), 16);
  EXPECT_EQ(f[0].corners.bytes(), f[1].corners.bytes());
  const TaskSpec wrong = TaskSpec::volume(2, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1));
  EXPECT_THROW(prepare_fields(sc.views, std::span(&wrong, 1)), Error);
  // Views of different point ranges cannot share a copy: each gets its own.
  const std::vector<FieldView> mixed{sc.views[0], sc.views[1].subview(Brick::slab(sc.grid, 2, 2, 0))};
  f = prepare_fields(mixed, p_s_and_ps_tasks());
  EXPECT_EQ(f[0].corners.record(), 8);
  EXPECT_EQ(f[1].corners.record(), 8);
  EXPECT_THROW(CornerField::joint(mixed[0], mixed[1]), Error);
}

// Adaptive sampling decides per volume task (a cell is split only for the tasks whose corners
// disagree), so a volume task's image from a K-task march is its one-task adaptive image, bit for
// bit, and the K-task march marches fewer samples than the K one-task marches together.
TEST(Compositing, AdaptiveVolumeTasksInOneMarchGiveTheirOneTaskImages) {
  const Scene sc;
  std::vector<TaskSpec> tasks = p_s_and_ps_tasks();
  tasks.push_back(TaskSpec::volume(0, TransferFunction::preset("diverging", 3), ValueWindow::absolute(-1, 1)));
  std::vector<PreparedField> fields{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  RenderOptions opt;
  opt.adaptive = true;
  opt.sample_distance = 1.0;
  for (const auto& cam : kCams) {
    std::vector<PartialImage> together(tasks.size());
    const RenderStats st = render_brick(cam, fields, tasks, together, opt);
    EXPECT_GT(st.interpolated_pixels, 0u);
    std::uint64_t separate_marched = 0;
    for (std::size_t t = 0; t < tasks.size(); ++t) {
      std::vector<PartialImage> one(1);
      separate_marched += render_brick(cam, fields, std::span(&tasks[t], 1), one, opt).marched_samples;
      EXPECT_EQ(one[0].rgba, together[t].rgba) << "task " << t;
      EXPECT_EQ(one[0].depth, together[t].depth) << "task " << t;
    }
    EXPECT_LT(st.marched_samples, separate_marched);
  }
}

TEST(Compositing, EmptySpaceSkippingDoesNotChangeImagesAndSkips) {
  const Scene sc;
  const auto& cam = kCams[1];
  std::vector<PreparedField> fields{PreparedField(sc.views[0]), PreparedField(sc.views[1])};
  for (std::size_t t = 0; t < sc.tasks.size(); ++t) {
    std::vector<PartialImage> a(1), b(1);
    RenderOptions on, off;
    off.skip_empty = false;
    const auto sa = render_brick(cam, fields, std::span(&sc.tasks[t], 1), a, on);
    const auto sb = render_brick(cam, fields, std::span(&sc.tasks[t], 1), b, off);
    EXPECT_EQ(sa.samples, sb.samples);
    for (std::size_t i = 0; i < a[0].rgba.size(); ++i) ASSERT_NEAR(a[0].rgba[i], b[0].rgba[i], 1e-5) << "task " << t;
    if (sc.tasks[t].kind == TaskKind::volume) {
      EXPECT_LT(sa.marched_samples, sb.marched_samples) << "task " << t;
    }
  }
}

// A dense field with one empty macro-cell: rays that miss it skip the macro-cell walk (one run),
// rays through it walk and skip its samples. Both must give the images of the unskipped march.
TEST(Compositing, DenseFieldWithOneEmptyCellSkipsOnlyThere) {
  const GridGeometry grid{{41, 33, 34}, {0, 0, 0}, {1, 1, 1}};
  std::vector<float> v(std::size_t(grid.dims[0]) * grid.dims[1] * grid.dims[2]);
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        // Points 15 … 25 on every axis are zero, so macro-cell (2, 2, 2) of size 8 is all zero.
        const bool hole = i >= 15 && i <= 25 && j >= 15 && j <= 25 && k >= 15 && k <= 25;
        v[(std::size_t(k) * grid.dims[1] + j) * grid.dims[0] + i] = hole ? 0.0f : 0.5f + 0.01f * float((i + 2 * j + 3 * k) % 7);
      }
  const std::vector<FieldView> views{FieldView::whole(grid, v.data())};
  const std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::preset("p-wave", 0.2f), ValueWindow::absolute(0, 1))};
  const camera::Camera cam({70, -50, 45}, {20, 16, 16}, {0, 0, 1}, 40, 64, 60);
  std::vector<PreparedField> fields{PreparedField(views[0])};
  std::vector<PartialImage> a(1), b(1);
  RenderOptions on, off;
  off.skip_empty = false;
  const auto sa = render_brick(cam, fields, tasks, a, on);
  const auto sb = render_brick(cam, fields, tasks, b, off);
  EXPECT_EQ(a[0].rgba, b[0].rgba);
  EXPECT_EQ(sa.samples, sb.samples);
  EXPECT_LT(sa.marched_samples, sb.marched_samples);  // the hole's samples were skipped
  EXPECT_GT(sa.marched_samples, sb.marched_samples * 9 / 10);  // and little else
  const auto ref = render_bricked(cam, views, tasks, {Brick::whole(grid)});
  for (int axis : {0, 2}) {
    const auto img = render_bricked(cam, views, tasks, {Brick::slab(grid, axis, 2, 0), Brick::slab(grid, axis, 2, 1)});
    EXPECT_LE(max_diff(img[0], ref[0]), 1) << "axis " << axis;
  }
}

TEST(Compositing, ManyTasksAreSplitIntoGroupsOfMarches) {
  GridGeometry g{{9, 9, 9}, {-4, -4, -4}, {1, 1, 1}};
  std::vector<float> v(9 * 9 * 9, 0.5f);
  std::vector<PreparedField> fields{PreparedField(FieldView::whole(g, v.data()))};
  std::vector<TaskSpec> tasks;
  for (int i = 0; i < 70; ++i)
    tasks.push_back(TaskSpec::volume(0, TransferFunction::constant({1, 1, 1}, 0.01f * (i + 1)), ValueWindow::absolute(0, 1)));
  std::vector<PartialImage> out(tasks.size());
  camera::Camera cam({0, 0, 30}, {0, 0, 0}, {0, 1, 0}, 30, 9, 9);
  render_brick(cam, fields, tasks, out);
  const float* a1 = out[0].rgba_at(4, 4);
  const float* a70 = out[69].rgba_at(4, 4);
  EXPECT_NEAR(a1[3], 1 - std::exp(-0.01 * 8), 1e-3);
  EXPECT_NEAR(a70[3], 1 - std::exp(-0.70 * 8), 1e-3);
}

TEST(Compositing, RejectsInconsistentInput) {
  const Scene sc;
  std::vector<PreparedField> fields{PreparedField(sc.views[0].subview(Brick::slab(sc.grid, 2, 2, 0))),
                                    PreparedField(sc.views[1])};
  std::vector<PartialImage> out(1);
  EXPECT_THROW(render_brick(kCams[0], fields, std::span(&sc.tasks[0], 1), out), Error);
  std::vector<PartialImage> none;
  EXPECT_THROW(render_brick(kCams[0], std::span(fields.data(), 1), std::span(&sc.tasks[0], 1), none), Error);
  FieldView bad = sc.views[0].subview(Brick::slab(sc.grid, 2, 2, 0));
  bad.points.lo[2] += 1;  // a ghost layer missing
  EXPECT_THROW(bad.validate(), Error);
  const TaskSpec wrong_field = TaskSpec::isosurface(5, 0.1f);
  EXPECT_THROW(render_brick(kCams[0], std::span(fields.data() + 1, 1), std::span(&wrong_field, 1), out), Error);
}

// Cameras inside the domain (issue 14): rays start inside a brick, and bricks lie in front of and
// behind the eye along different rays. The march clamps each ray's entry at t = 0 and keeps the global
// sample positions, so the bricks still composite to the single-brick image. The full march
// (equirect_adaptive off) within 1/255; the default 360° frames, sampled adaptively on the sphere
// (equirect_sampling.hpp), decide their refinement per brick and composite as adaptive images do
// (Quality.AdaptiveSamplingRefinesEdgesAndCompositesAcrossBricks): within 40 dB, and every pixel's
// depth is the full march's, bit for bit, whichever brick the eye is in or on.
TEST(Compositing, CamerasInsideTheDomainMatchTheSingleBrickImage) {
  const Scene sc;
  RenderOptions full;
  full.equirect_adaptive = false;
  const camera::Camera inside[] = {
      camera::Camera({-3, 2, 1}, {10, 4, 0}, {0, 0, 1}, 90, 36, 30),
      camera::Camera({4, -6, -2}, {4, 10, -2}, {0, 0, 1}, 60, 48, 24, camera::Projection::equirectangular),
      // On a brick face of the 2- and 4-slab decompositions along z (z = 0 is point 16 of 33).
      camera::Camera({1, 1, 0}, {-5, 1, 3}, {0, 0, 1}, 60, 48, 24, camera::Projection::equirectangular),
  };
  for (std::size_t ci = 0; ci < std::size(inside); ++ci) {
    const camera::Camera& cam = inside[ci];
    const auto ref = render_bricked(cam, sc.views, sc.tasks, {Brick::whole(sc.grid)}, full);
    const auto ref_sphere = render_bricked(cam, sc.views, sc.tasks, {Brick::whole(sc.grid)});
    for (int axis : {2, 0})
      for (int n : {2, 3, 4}) {
        const auto img = render_bricked(cam, sc.views, sc.tasks, sc.slabs(axis, n), full);
        const auto ordered = render_bricked(cam, sc.views, sc.tasks, sc.slabs(axis, n), full, true);
        const auto sphere = render_bricked(cam, sc.views, sc.tasks, sc.slabs(axis, n), {}, true);
        for (std::size_t t = 0; t < sc.tasks.size(); ++t) {
          EXPECT_LE(max_diff(img[t], ref[t]), 1) << "camera " << ci << ", axis " << axis << ", " << n << " bricks, task " << t;
          EXPECT_LE(max_diff(ordered[t], ref[t]), 1) << "ordered, camera " << ci << ", axis " << axis << ", " << n
                                                     << " bricks, task " << t;
          if (cam.projection() == camera::Projection::equirectangular) {
            EXPECT_GE(psnr(sphere[t], ref_sphere[t]), 40.0) << "sphere, camera " << ci << ", axis " << axis << ", " << n
                                                          << " bricks, task " << t;
          }
        }
        // The bricks' partial depths are the full march's (the eye-in-brick shortcut included). A
        // max-blend image's depth is its maximum's key, which adaptive sampling interpolates as it
        // does the colour: only the entry depths of over-blend images are exact.
        for (const Brick& b : sc.slabs(axis, n)) {
          std::vector<PreparedField> fields;
          for (const FieldView& f : sc.views) fields.emplace_back(f.subview(b));
          std::vector<PartialImage> a(sc.tasks.size()), d(sc.tasks.size());
          render_brick(cam, fields, sc.tasks, a);
          render_brick(cam, fields, sc.tasks, d, full);
          for (std::size_t t = 0; t < sc.tasks.size(); ++t)
            if (blend_of(sc.tasks[t].kind) == Blend::over) {
              ASSERT_TRUE(a[t].depth == d[t].depth) << "camera " << ci << ", axis " << axis << ", " << n << " bricks, task " << t;
            }
        }
      }
  }
}

// Known answer: a small bright blob at a known position appears at the (longitude, latitude) pixel
// that Camera::project predicts, within one pixel, for equirectangular cameras inside and outside.
TEST(Equirectangular, PointSourceLandsOnThePredictedPixel) {
  const GridGeometry grid{{41, 41, 41}, {-20, -20, -20}, {1, 1, 1}};
  struct Case {
    Vec3 blob, eye, look, up;
  } cases[] = {
      {{6, -4, 3}, {-5, 2, -1}, {0, 10, 0}, {0, 0, 1}},        // inside, blob to the right and behind
      {{-12, 9, -8}, {3, 3, 3}, {10, 3, 3}, {0, 0, -1}},       // inside, z down, blob behind
      {{2, 3, 5}, {-70, 20, 25}, {0, 0, 0}, {0, 0, 1}},        // outside, blob near the centre column
      {{15, -15, 0}, {0, 0, 60}, {0, 0, 0}, {0, 1, 0}},        // outside, above the domain
  };
  for (const Case& c : cases) {
    std::vector<float> f(std::size_t(41) * 41 * 41);
    for (int k = 0; k < 41; ++k)
      for (int j = 0; j < 41; ++j)
        for (int i = 0; i < 41; ++i) {
          const Vec3 p{-20.0 + i, -20.0 + j, -20.0 + k};
          const double r2 = dot(p - c.blob, p - c.blob);
          f[std::size_t(i) + 41 * (std::size_t(j) + 41 * std::size_t(k))] = float(std::exp(-r2 / (0.9 * 0.9)));
        }
    const std::vector<FieldView> views{FieldView::whole(grid, f.data())};
    const std::vector<TaskSpec> tasks{
        TaskSpec::volume(0, TransferFunction::preset("p-wave", 0.5f), ValueWindow::absolute(0, 1))};
    const camera::Camera cam(c.eye, c.look, c.up, 45, 360, 180, camera::Projection::equirectangular);
    const Image img = render_bricked(cam, views, tasks, {Brick::whole(grid)})[0];
    double px = 0, py = 0;
    ASSERT_TRUE(cam.project(c.blob, px, py));
    // Brightest pixel, then the brightness-weighted centroid of its 7x7 neighbourhood (longitude wraps).
    auto lum = [&](int x, int y) {
      const std::uint8_t* q = img.at(((x % 360) + 360) % 360, y);
      return double(q[0]) + q[1] + q[2];
    };
    int bx = 0, by = 0;
    for (int y = 0; y < 180; ++y)
      for (int x = 0; x < 360; ++x)
        if (lum(x, y) > lum(bx, by)) bx = x, by = y;
    double lo = 1e9;
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx) lo = std::min(lo, lum(bx + dx, std::clamp(by + dy, 0, 179)));
    double sw = 0, sx = 0, sy = 0;
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx) {
        const int y = std::clamp(by + dy, 0, 179);
        const double w = lum(bx + dx, y) - lo;
        sw += w, sx += w * (bx + dx + 0.5), sy += w * (y + 0.5);
      }
    ASSERT_GT(sw, 0);
    double ex = sx / sw - px;
    ex -= 360 * std::round(ex / 360);
    EXPECT_LE(std::abs(ex), 1.0) << "blob " << c.blob.x << "," << c.blob.y << "," << c.blob.z << " predicted " << px;
    EXPECT_LE(std::abs(sy / sw - py), 1.0) << "blob " << c.blob.x << "," << c.blob.y << "," << c.blob.z << " predicted " << py;
  }
}

// finish_image() rounds every colour exactly as std::lround(clamp(c, 0, 1) * 255) (NaN as 0), also at
// the float values next to the rounding ties; finishing into a used image or after an image with a
// different outline gives the same pixels as a fresh call (the outline's coverage is kept per thread
// and cleared sparsely, so a left-over would show here).
TEST(Compositing, FinishImageRoundsLikeLroundAndReusesItsBuffers) {
  const GridGeometry g{{20, 16, 12}, {-9.5, -7.5, -5.5}, {1, 1, 1}};
  const camera::Camera cams[] = {camera::Camera({30, -25, 20}, {0, 0, 0}, {0, 0, 1}, 40, 64, 48),
                                 camera::Camera({-20, 30, -15}, {1, 0, 0}, {0, 0, 1}, 50, 64, 48)};
  PartialImage p;
  p.reset(64, 48, {5, 3, 60, 41});
  // Colours c with c * 255 at and around the ties n + 0.5, the clamps, and NaN.
  std::vector<float> values{0.0f, 1.0f, -0.25f, 1.75f, std::nanf("")};
  for (int n = 0; n < 255; n += 7) {
    const float tie = (float(n) + 0.5f) / 255.0f;
    values.insert(values.end(), {tie, std::nextafter(tie, 0.0f), std::nextafter(tie, 1.0f)});
  }
  std::uint32_t state = 12345;
  auto next = [&] { return (state = state * 1664525u + 1013904223u) >> 8; };
  for (std::size_t i = 0; i < p.rgba.size(); i += 4) {
    for (int k = 0; k < 3; ++k) p.rgba[i + std::size_t(k)] = values[next() % values.size()];
    // Alpha 1 or 0 makes v + (1 - α)·bg exact whether or not the compiler fuses it into an FMA (the
    // render module may, with -march=native); other alphas are checked to within 1.
    p.rgba[i + 3] = (i / 4) % 3 == 0 ? 0.0f : (i / 4) % 3 == 1 ? 1.0f : float(next() % 1000) / 999.0f;
  }
  const Rgb bg{0.1f, 0.2f, 0.3f};
  auto byte = [](float c) { return std::uint8_t(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)); };
  const Image plain = finish_image(p, cams[0], g, bg, {false});
  const float bgc[3] = {bg.r, bg.g, bg.b};
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      for (int k = 0; k < 3; ++k) {
        const bool in = p.rect.contains(x, y);
        const float a = in ? p.rgba_at(x, y)[3] : 0.0f;
        const float c = in ? p.rgba_at(x, y)[k] + (1 - a) * bgc[k] : bgc[k];
        const int want = std::isnan(c) ? 0 : byte(c);
        if (a == 0.0f || a == 1.0f)
          ASSERT_EQ(plain.at(x, y)[k], want) << x << "," << y << " channel " << k << " value " << c;
        else
          ASSERT_LE(std::abs(plain.at(x, y)[k] - want), 1) << x << "," << y << " channel " << k << " value " << c;
      }
  // Fresh images per camera, then the same into one reused image, alternating cameras and outlines.
  const Image fresh[2] = {finish_image(p, cams[0], g, bg), finish_image(p, cams[1], g, bg)};
  EXPECT_GT(max_diff(fresh[0], plain), 0);  // the outline is there
  Image reused(64, 48, 4);
  std::fill(reused.pixels.begin(), reused.pixels.end(), std::uint8_t(77));
  for (int round = 0; round < 4; ++round) {
    finish_image_into(p, cams[round % 2], g, reused, bg);
    EXPECT_EQ(reused.pixels, fresh[round % 2].pixels) << "round " << round;
    finish_image_into(p, cams[round % 2], g, reused, bg, {false});
    EXPECT_EQ(reused.pixels, plain.pixels) << "round " << round;
  }
}

// The outline's coverage is kept from one call to the next (K images of one camera in a row): every
// change of what it depends on (camera, domain, line width) must redraw it. Each call is checked
// against the same call on a new thread, whose coverage starts empty.
TEST(Compositing, FinishImageKeepsTheOutlineOnlyForTheSameCameraDomainAndWidth) {
  const GridGeometry g1{{20, 16, 12}, {-9.5, -7.5, -5.5}, {1, 1, 1}}, g2{{20, 16, 12}, {-9.5, -7.5, -5.5}, {1.2, 1, 1}};
  const camera::Camera c1({30, -25, 20}, {0, 0, 0}, {0, 0, 1}, 40, 64, 48);
  const camera::Camera c2({30, -25, 20}, {0, 0, 0}, {0, 0, 1}, 42, 64, 48);  // only the field of view differs
  PartialImage p;
  p.reset(64, 48, {5, 3, 60, 41});
  for (std::size_t i = 0; i < p.rgba.size(); i += 4) p.rgba[i + 1] = p.rgba[i + 3] = float(i % 7) / 7.0f;
  const Rgb bg{0.1f, 0.2f, 0.3f};
  OutlineStyle thin, thick;
  thick.width = 3.0f;
  struct Call {
    const camera::Camera* cam;
    const GridGeometry* grid;
    OutlineStyle style;
  };
  const Call calls[] = {{&c1, &g1, thin}, {&c1, &g1, thin}, {&c1, &g1, thick}, {&c1, &g2, thick},
                        {&c2, &g2, thick}, {&c2, &g2, thin},  {&c1, &g1, thin}};
  Image out;
  for (std::size_t i = 0; i < std::size(calls); ++i) {
    const Call& c = calls[i];
    finish_image_into(p, *c.cam, *c.grid, out, bg, c.style);
    Image fresh;
    std::thread([&] { fresh = finish_image(p, *c.cam, *c.grid, bg, c.style); }).join();
    EXPECT_EQ(out.pixels, fresh.pixels) << "call " << i;
    if (i > 0 && (c.cam != calls[i - 1].cam || c.grid != calls[i - 1].grid || c.style.width != calls[i - 1].style.width)) {
      Image before;
      const Call& b = calls[i - 1];
      std::thread([&] { before = finish_image(p, *b.cam, *b.grid, bg, b.style); }).join();
      EXPECT_NE(fresh.pixels, before.pixels) << "call " << i << " changes nothing the outline shows";
    }
  }
}

// A camera inside the domain with a 360° frame (issue 32): all twelve box edges are drawn as the arcs
// they project to, also across the frame's left/right seam; the compass adds the horizon of its sky
// frame, ticks and N/E/S/W letters above the cardinal directions and nothing far from the horizon; a
// perspective frame is unchanged by it.
TEST(Compositing, EquirectangularFramesShowTheBoxAsArcsAndACompass) {
  const GridGeometry g{{21, 17, 13}, {-10, -8, -6}, {1, 1, 1}};  // the box [-10, 10] x [-8, 8] x [-6, 6]
  const camera::SkyFrame ned = camera::SkyFrame::of(camera::UpAxis::z_down);  // north +x, east +y, sky -z
  const int w = 360, h = 180;                                                  // 1 pixel per degree
  const Vec3 eye{2, 1, 0.5};
  const camera::Camera cam(eye, eye + ned.north, ned.sky, 90, w, h, camera::Projection::equirectangular);
  PartialImage p;
  p.reset(w, h, {0, 0, 0, 0});
  OutlineStyle box_only, with_compass, compass_only;
  box_only.compass = false;
  with_compass.sky = compass_only.sky = ned;
  compass_only.box = false;
  const Image a = finish_image(p, cam, g, {0, 0, 0}, box_only), b = finish_image(p, cam, g, {0, 0, 0}, with_compass);
  const Image c = finish_image(p, cam, g, {0, 0, 0}, compass_only);
  auto lit_near = [&](const Image& img, double px, double py, int r) {
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const int x = ((int(std::floor(px)) + dx) % w + w) % w, y = int(std::floor(py)) + dy;
        if (y >= 0 && y < h && img.at(x, y)[0] > 0) return true;
      }
    return false;
  };
  const Vec3 lo = g.domain_lo(), hi = g.domain_hi();
  for (int e = 0; e < 12; ++e) {
    const int ax = e / 4, b1 = (ax + 1) % 3, b2 = (ax + 2) % 3;
    Vec3 s = lo, t = lo;
    s[b1] = t[b1] = (e & 1) ? hi[b1] : lo[b1];
    s[b2] = t[b2] = (e & 2) ? hi[b2] : lo[b2];
    t[ax] = hi[ax];
    for (const double f : {0.0, 0.2, 0.5, 0.8, 1.0}) {
      double px, py;
      ASSERT_TRUE(cam.project(s + (t - s) * f, px, py));
      EXPECT_TRUE(lit_near(a, px, py, 1)) << "edge " << e << " at " << f << ": pixel " << px << ", " << py;
      EXPECT_FALSE(lit_near(c, px, py, 0) && std::abs(py - h / 2) > 12) << "box edge drawn with box = false";
    }
  }
  // The edge x = −10 (south), z = 0.5 ± ... crosses the seam behind the camera: both sides of the frame show it.
  double sx, sy;
  ASSERT_TRUE(cam.project({-10, 1, -6}, sx, sy));
  EXPECT_TRUE(a.at(0, int(sy))[0] > 0 || a.at(0, int(sy) + 1)[0] > 0 || a.at(0, int(sy) - 1)[0] > 0);
  EXPECT_TRUE(a.at(w - 1, int(sy))[0] > 0 || a.at(w - 1, int(sy) + 1)[0] > 0 || a.at(w - 1, int(sy) - 1)[0] > 0);
  // The compass's pixels: within 12 degrees above and 4 below the horizon (row 90), on it in almost
  // every column, and letters above north (column 180), east (270), south (0) and west (90).
  int horizon_columns = 0;
  for (int x = 0; x < w; ++x) horizon_columns += c.at(x, 89)[0] > 0 || c.at(x, 90)[0] > 0;
  EXPECT_GE(horizon_columns, w - 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (c.at(x, y)[0] > 0) {
        ASSERT_TRUE(y >= 90 - 12 && y <= 90 + 4) << "compass pixel at " << x << ", " << y;
      }
  for (const int col : {180, 270, 0, 90}) {
    int letter = 0;
    for (int y = 90 - 11; y <= 90 - 4; ++y)
      for (int dx = -3; dx <= 3; ++dx) letter += c.at((col + dx + w) % w, y)[0] > 0;
    EXPECT_GE(letter, 10) << "no letter above column " << col;
  }
  int between = 0;  // above the horizon half-way between two letters: only the 45-degree tick or nothing
  for (int y = 90 - 11; y <= 90 - 4; ++y) between += c.at(180 + 22, y)[0] > 0;
  EXPECT_EQ(between, 0);
  // With the box too, every box pixel is still there (the compass only adds coverage).
  for (std::size_t i = 0; i < a.pixels.size(); ++i) ASSERT_GE(b.pixels[i], a.pixels[i]) << "pixel byte " << i;
  // Perspective frames have no compass.
  const camera::Camera persp(eye, eye + ned.north, ned.sky, 60, 96, 64);
  PartialImage q;
  q.reset(96, 64, {0, 0, 0, 0});
  EXPECT_EQ(finish_image(q, persp, g, {0, 0, 0}, box_only).pixels, finish_image(q, persp, g, {0, 0, 0}, with_compass).pixels);
}
