// The task plan (issue 30): render's --task shorthand means the [[task]] tables it prints, and the
// plan built from either is the same (entries, axes, specs resolved against a reference).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.hpp"
#include "insitu/task_plan.hpp"

using namespace panoptes;

namespace {

const render::GridGeometry kGrid{{20, 16, 12}, {-1, 0, 2}, {0.5, 1, 2}};

TEST(TaskPlan, ShorthandMeansTheTomlTablesItPrints) {
  const std::vector<std::string> texts{"volume:hot", "volume:diverging", "volume:p-wave:0:0.8", "iso:0.3",
                                       "slice:y:0.25:rainbow:-2:3", "iso:-0.2", "slice:z:1"};
  const std::vector<insitu::TaskConfig> tasks = insitu::tasks_from_shorthand(texts, "v");
  ASSERT_EQ(tasks.size(), 6u);  // the two iso: form one sweep
  std::string toml = "[schedule]\nevery_steps = 1\n";
  for (const auto& t : tasks) toml += insitu::task_table_toml(t) + "\n";
  const insitu::SessionConfig cfg = insitu::parse_session_config_text(toml, "printed tasks");
  const insitu::TaskPlan a(tasks, kGrid), b(cfg.tasks, kGrid);
  ASSERT_EQ(a.size(), 7u);
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.tasks()[i].entry, b.tasks()[i].entry) << i;
  EXPECT_EQ(a.axes(), b.axes());
  ASSERT_EQ(a.axes().size(), 1u);
  EXPECT_EQ(a.axes()[0].name, "isovalue");
  EXPECT_EQ(a.axes()[0].values, (std::vector<double>{0.3, -0.2}));
  EXPECT_EQ(a.tasks()[3].entry.name, "iso 0.3");
  EXPECT_EQ(a.field_names(), std::vector<std::string>{"v"});

  // Relative windows follow the reference; absolute ones do not.
  std::vector<render::TaskSpec> specs;
  a.resolve({2.5}, specs);
  ASSERT_EQ(specs.size(), a.size());
  EXPECT_EQ(specs[0].reference, 2.5);  // volume:hot, relative [0, 1]
  EXPECT_EQ(specs[0].window.lo, 0.0);
  EXPECT_EQ(specs[1].window.lo, -1.0);  // diverging: [-ref, ref]
  EXPECT_FALSE(a.tasks()[2].relative);  // LO:HI is absolute
  EXPECT_FALSE(a.tasks()[5].relative);
  EXPECT_TRUE(a.tasks()[6].relative);
  // Slice positions are fractions of the grid's domain.
  EXPECT_DOUBLE_EQ(specs[5].slice_position, 0 + 0.25 * 15 * 1.0);
  EXPECT_DOUBLE_EQ(specs[6].slice_position, 2 + 1.0 * 11 * 2.0);
}

TEST(TaskPlan, ShorthandErrorsNameTheOption) {
  auto message = [](const std::string& text) {
    try {
      insitu::tasks_from_shorthand({text}, "v");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("volume:nope").find("--task \"volume:nope\": unknown preset"), std::string::npos);
  EXPECT_NE(message("volume:hot:1:0").find("expected LO < HI"), std::string::npos);
  EXPECT_NE(message("slice:w:0.5").find("slice axis \"w\""), std::string::npos);
  EXPECT_NE(message("slice:x:1.5").find("expected a fraction"), std::string::npos);
  EXPECT_NE(message("iso:abc").find("\"abc\" is not a number"), std::string::npos);
  EXPECT_NE(message("cube:1").find("expected volume:PRESET"), std::string::npos);
  EXPECT_THROW(insitu::tasks_from_shorthand({"iso:1", "iso:1"}, "v"), Error);
  EXPECT_THROW(insitu::tasks_from_shorthand({"volume:hot", "volume:hot"}, "v"), Error);
}

// One vocabulary (issue 30): the TOML `type` and the shorthand's first word are render::TaskKind's
// words; "volume2" is a render volume reading two fields; each table expands to planned_task_count()
// tasks, the number the plan builds.
TEST(TaskPlan, KindsAreRenderTaskKinds) {
  const insitu::SessionConfig cfg = insitu::parse_session_config_text(
      "[schedule]\nevery_steps = 1\n"
      "[[task]]\nname = \"v\"\ntype = \"volume\"\nfield = \"a\"\nwindows = [[0, 1], [0, 0.5]]\n"
      "[[task]]\nname = \"ps\"\ntype = \"volume2\"\nfields = [\"a\", \"b\"]\n"
      "[[task]]\nname = \"iso\"\ntype = \"isosurface\"\nfield = \"a\"\nisovalues = [0.1, 0.2, 0.3]\n"
      "[[task]]\nname = \"s\"\ntype = \"slice\"\nfield = \"b\"\n",
      "kinds");
  ASSERT_EQ(cfg.tasks.size(), 4u);
  EXPECT_EQ(cfg.tasks[0].kind, render::TaskKind::volume);
  EXPECT_EQ(cfg.tasks[1].kind, render::TaskKind::volume);
  EXPECT_EQ(cfg.tasks[1].fields.size(), 2u);
  EXPECT_EQ(cfg.tasks[2].kind, render::TaskKind::isosurface);
  EXPECT_EQ(cfg.tasks[3].kind, render::TaskKind::slice);
  const insitu::TaskPlan plan(cfg.tasks, kGrid);
  std::size_t expanded = 0;
  for (const auto& t : cfg.tasks) expanded += insitu::planned_task_count(t);
  EXPECT_EQ(expanded, plan.size());
  EXPECT_EQ(plan.size(), 2u + 1 + 3 + 1);
  EXPECT_EQ(plan.tasks()[2].spec.kind, render::TaskKind::volume);
  EXPECT_EQ(plan.tasks()[2].spec.field2, 1);
  // The volume2 table prints back as volume2; the shorthand takes render's full word as well as "iso".
  EXPECT_NE(insitu::task_table_toml(cfg.tasks[1]).find("type = \"volume2\"\nfields = [\"a\", \"b\"]"), std::string::npos);
  EXPECT_EQ(insitu::parse_task_shorthand("isosurface:0.5", "a").kind, render::TaskKind::isosurface);
  EXPECT_EQ(insitu::parse_task_shorthand("iso:0.5", "a").isovalues, std::vector<double>{0.5});
  try {
    (void)insitu::parse_session_config_text("[schedule]\nevery_steps = 1\n[[task]]\nname = \"c\"\ntype = \"cube\"\nfield = \"a\"\n", "kinds");
    ADD_FAILURE() << "type = \"cube\" accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("task[0].type: \"cube\"; expected volume, volume2, isosurface, slice or mip"),
              std::string::npos)
        << e.what();
  }
  // A configuration built in code with an empty sweep is refused by validate().
  insitu::SessionConfig empty = cfg;
  empty.tasks[2].isovalues.clear();
  EXPECT_THROW(empty.validate(), Error);
}

}  // namespace

// Every kind (render::kTaskKinds) has its keys in the configuration help and a --task shorthand; the
// user-visible lists are built from that one list, so a new kind appears in all of them or fails here.
TEST(TaskPlan, EveryKindIsInTheHelpTheShorthandAndTheErrors) {
  const std::string help = insitu::config_keys_help();
  const std::string syntax = insitu::task_shorthand_syntax();
  for (const render::TaskKind k : render::kTaskKinds) {
    const std::string word = render::to_string(k);
    EXPECT_NE(help.find("\n  " + word + ":"), std::string::npos) << word << " has no keys in the help";
    EXPECT_NE(render::task_kind_words().find(word), std::string::npos) << word;
    const std::string first = k == render::TaskKind::isosurface ? "iso" : word;
    EXPECT_NE(syntax.find(first + ":"), std::string::npos) << word << " has no shorthand in: " << syntax;
  }
  EXPECT_NE(help.find("type = volume, volume2, isosurface, slice or mip"), std::string::npos) << help;
}

// MIP (issue 43): the TOML table, the shorthand and the printed table mean the same task; the window
// follows the reference as a volume's; the manifest says "mip" with its colour map.
TEST(TaskPlan, MipFromTomlAndShorthand) {
  const insitu::SessionConfig cfg = insitu::parse_session_config_text(
      "[schedule]\nevery_steps = 1\n"
      "[[task]]\nname = \"m\"\ntype = \"mip\"\nfield = \"a\"\npreset = \"hot\"\n"
      "[[task]]\nname = \"mip:diverging:-2:2\"\ntype = \"mip\"\nfield = \"a\"\npreset = \"diverging\"\n"
      "relative = false\nwindow = [-2, 2]\n",
      "mip");
  const std::vector<insitu::TaskConfig> shorthand = insitu::tasks_from_shorthand({"mip:hot", "mip:diverging:-2:2"}, "a");
  ASSERT_EQ(cfg.tasks.size(), 2u);
  ASSERT_EQ(shorthand.size(), 2u);
  const insitu::TaskPlan a(cfg.tasks, kGrid), b(shorthand, kGrid);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.tasks()[0].spec.kind, render::TaskKind::mip);
  EXPECT_EQ(a.tasks()[0].entry.method, "mip");
  EXPECT_TRUE(a.tasks()[0].relative);
  EXPECT_FALSE(a.tasks()[1].relative);
  EXPECT_EQ(a.tasks()[1].entry, b.tasks()[1].entry);
  EXPECT_EQ(a.tasks()[0].entry.parameters, b.tasks()[0].entry.parameters);
  // Printed back, the tables parse to the same plan.
  std::string toml = "[schedule]\nevery_steps = 1\n";
  for (const auto& t : shorthand) toml += insitu::task_table_toml(t) + "\n";
  const insitu::TaskPlan c(insitu::parse_session_config_text(toml, "printed").tasks, kGrid);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(c.tasks()[i].entry, b.tasks()[i].entry) << i;
  std::vector<render::TaskSpec> specs;
  a.resolve({3.0}, specs);
  EXPECT_EQ(specs[0].reference, 3.0);
  EXPECT_EQ(specs[1].window.hi, 2.0);
  // Keys of other kinds are refused.
  EXPECT_THROW(insitu::parse_session_config_text(
                   "[schedule]\nevery_steps = 1\n[[task]]\nname = \"m\"\ntype = \"mip\"\nfield = \"a\"\nisovalue = 1\n", "mip"),
               Error);
  EXPECT_THROW(insitu::tasks_from_shorthand({"mip:hot:1"}, "a"), Error);
}
