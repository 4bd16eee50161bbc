// The march-plan room (march_plan.hpp): every task kind compiles to its march kind and masks, the
// macro-cells a task can skip are the ones where it sees nothing (a MIP: values at or below its
// window), and bad tasks are refused with the value and what was expected.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.hpp"
#include "render/march_plan.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

// A 17³ grid whose field is 0 for x < 8 and rises to 1 beyond: half the macro-cells see nothing
// above a window starting at 0.
struct Half {
  GridGeometry grid{{17, 17, 17}, {0, 0, 0}, {1, 1, 1}};
  std::vector<float> f;
  Half() {
    f.resize(17 * 17 * 17);
    for (int k = 0; k < 17; ++k)
      for (int j = 0; j < 17; ++j)
        for (int i = 0; i < 17; ++i) f[std::size_t(i + 17 * (j + 17 * k))] = i < 9 ? 0.0f : float(i - 8) / 8;
  }
};

}  // namespace

TEST(MarchPlan, EveryKindCompilesToItsMarchKindAndMasks) {
  const Half h;
  std::vector<PreparedField> fields;
  fields.emplace_back(FieldView::whole(h.grid, h.f.data()));
  for (const TaskKind k : kTaskKinds) {
    TaskSpec t;
    switch (k) {
      case TaskKind::volume: t = TaskSpec::volume(0, TransferFunction::preset("hot"), ValueWindow::absolute(0, 1)); break;
      case TaskKind::isosurface: t = TaskSpec::isosurface(0, 0.5f); break;
      case TaskKind::slice: t = TaskSpec::slice(0, 1, 4.0, TransferFunction::preset("rainbow"), ValueWindow::absolute(0, 1)); break;
      case TaskKind::mip: t = TaskSpec::mip(0, TransferFunction::preset("hot"), ValueWindow::absolute(0, 1)); break;
    }
    ASSERT_EQ(t.kind, k) << "no example for kind " << to_string(k);
    const std::vector<TaskSpec> tasks{t};
    const march::MarchPlan p = march::compile_march_plan(fields, tasks, RenderOptions{});
    SCOPED_TRACE(to_string(k));
    EXPECT_EQ(p.rt[0].kind, march::march_kind(t));
    EXPECT_EQ(p.max_mask, blend_of(k) == Blend::max ? 1u : 0u);  // the blend decides what the depth holds
    EXPECT_EQ(p.march_mask, k == TaskKind::slice ? 0u : 1u);      // slices are intersected, not marched
    EXPECT_EQ(p.iso_mask, k == TaskKind::isosurface ? 1u : 0u);
    EXPECT_EQ(p.mip_mask, k == TaskKind::mip ? 1u : 0u);
  }
  const TaskSpec v2 = TaskSpec::volume2(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, 1), 0,
                                        TransferFunction::preset("s-wave"), ValueWindow::absolute(0, 1));
  EXPECT_EQ(march::march_kind(v2), march::MarchKind::volume2);
}

TEST(MarchPlan, AMipSkipsOnlyCellsAtOrBelowItsWindow) {
  const Half h;
  std::vector<PreparedField> fields;
  fields.emplace_back(FieldView::whole(h.grid, h.f.data()), 4);  // 4³ macro-cells: 4 per axis
  const std::vector<TaskSpec> tasks{TaskSpec::mip(0, TransferFunction::preset("hot"), ValueWindow::absolute(0, 1)),
                                    TaskSpec::mip(0, TransferFunction::preset("hot"), ValueWindow::absolute(-1, 1))};
  const march::MarchPlan p = march::compile_march_plan(fields, tasks, RenderOptions{});
  int seen = 0, skipped = 0;
  for (int m = 0; m < int(p.active.size()); ++m) {
    const int mx = m % p.mcount[0];
    // Cells 0 and 1 along x hold points 0..8 (+ a one-point margin: up to 9 for cell 1), all 0 but
    // cell 1's margin; the window [0, 1] sees nothing in cell 0. A window from -1 sees 0 everywhere.
    if (mx == 0) EXPECT_EQ(p.active[std::size_t(m)] & 1u, 0u) << "cell " << m;
    else EXPECT_EQ(p.active[std::size_t(m)] & 1u, 1u) << "cell " << m;
    EXPECT_EQ(p.active[std::size_t(m)] & 2u, 2u) << "cell " << m;
    (p.active[std::size_t(m)] & 1u ? seen : skipped)++;
  }
  EXPECT_GT(skipped, 0);
  EXPECT_GT(seen, 0);
}

TEST(MarchPlan, RefusalsNameTheValueAndTheExpectation) {
  const Half h;
  std::vector<PreparedField> fields;
  fields.emplace_back(FieldView::whole(h.grid, h.f.data()));
  auto message = [&](const TaskSpec& t) {
    try {
      const std::vector<TaskSpec> tasks{t};
      (void)march::compile_march_plan(fields, tasks, RenderOptions{});
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(TaskSpec::slice(0, 5, 1.0, TransferFunction::preset("hot"), ValueWindow::absolute(0, 1)))
                .find("slice axis 5; expected 0 (x), 1 (y) or 2 (z)"),
            std::string::npos);
  EXPECT_NE(message(TaskSpec::mip(3, TransferFunction::preset("hot"), ValueWindow::absolute(0, 1)))
                .find("field 3 but 1 fields were given"),
            std::string::npos);
  EXPECT_NE(message(TaskSpec::isosurface(0, NAN)).find("isovalue is not finite"), std::string::npos);
}
