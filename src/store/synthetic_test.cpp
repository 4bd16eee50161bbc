#include "store/synthetic.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace panoptes::store {
namespace {

// Issue 43: the key tests need camera shells (Z / X) and several parameter axes (A / Shift+A / PgUp).
TEST(Synthetic, ShellsAndAxes) {
  SyntheticOptions o;
  o.cameras = 4;
  o.shells = 3;
  o.axes = {3, 2};
  const Manifest m = synthetic_manifest(o);
  ASSERT_EQ(m.cameras.size(), 12u);
  ASSERT_EQ(m.graph.neighbours.size(), 12u);
  for (int id = 0; id < 12; ++id) {
    const auto& n = m.graph.neighbours[std::size_t(id)];
    const int shell = id / 4;
    EXPECT_EQ(m.cameras[std::size_t(id)].labels.shell, shell);
    EXPECT_EQ(n.in, shell < 2 ? id + 4 : -1) << id;
    EXPECT_EQ(n.out, shell > 0 ? id - 4 : -1) << id;
    EXPECT_EQ(n.right / 4, shell) << "the ring stays on its shell";
    EXPECT_GT(norm(m.cameras[std::size_t(id)].position), 3 / (1 + 0.5 * shell) - 1e-9) << "inner shells are closer";
    EXPECT_LT(norm(m.cameras[std::size_t(id)].position), 3 / (1 + 0.5 * shell) + 1e-9);
  }
  ASSERT_EQ(m.axes.size(), 2u);
  EXPECT_EQ(m.axes[0].name, "isovalue");
  EXPECT_EQ(m.axes[1].name, "opacity");
  ASSERT_EQ(m.tasks.size(), 6u);
  EXPECT_EQ(m.tasks[4].axes, (std::vector<AxisPosition>{{"isovalue", 1}, {"opacity", 1}})) << "the first axis varies fastest";
  EXPECT_EQ(m.tasks[4].name, "isovalue 1 opacity 1");

  // Without the options: one shell, one "isovalue" axis of `tasks` values, as before.
  const Manifest plain = synthetic_manifest(SyntheticOptions{});
  EXPECT_EQ(plain.axes.size(), 1u);
  EXPECT_EQ(plain.tasks[1].name, "isovalue 1");
  EXPECT_EQ(plain.graph.neighbours[0].in, -1);

  o.axes = {3, 0};
  EXPECT_THROW(synthetic_manifest(o), Error);
  o.axes = {};
  o.lattice = {2, 2, 2};
  EXPECT_THROW(synthetic_manifest(o), Error) << "shells inside a lattice";
}

}  // namespace
}  // namespace panoptes::store
