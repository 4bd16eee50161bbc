#include "player/headless.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.hpp"
#include "core/frame_stamp.hpp"
#include "core/png.hpp"
#include "player/test_db.hpp"
#include "store/synthetic.hpp"

namespace panoptes::player {
namespace {

using testing::TempDir;

TEST(Script, ParsesEveryCommand) {
  const auto s = parse_script(
      "# a fly-around\n"
      "t=0 pause\n"
      "t=0.5 key=Right   # rotate\n"
      "\n"
      "t=1.0 key=Shift+Tab\n"
      "t=1.2 seek=10\n"
      "t=1.3 camera=4\n"
      "t=1.4 task=2\n"
      "t=1.4 task=iso_high\n"
      "t=1.5 axis=isovalue:+1\n"
      "t=1.6 snap=1,0,-0.5\n"
      "t=1.7 speed=2\n"
      "t=1.8 play\n"
      "t=2 end\n");
  ASSERT_EQ(s.size(), 12u);
  EXPECT_EQ(s[0].kind, ScriptCommand::Kind::pause);
  EXPECT_EQ(s[1].kind, ScriptCommand::Kind::key);
  EXPECT_EQ(s[1].action, Action::camera_right);
  EXPECT_DOUBLE_EQ(s[1].t, 0.5);
  EXPECT_EQ(s[1].line, 3);
  EXPECT_EQ(s[2].action, Action::previous_task);
  EXPECT_EQ(s[3].value, 10);
  EXPECT_EQ(s[4].value, 4);
  EXPECT_EQ(s[5].value, 2);
  EXPECT_EQ(s[6].value, -1);
  EXPECT_EQ(s[6].name, "iso_high");
  EXPECT_EQ(s[7].name, "isovalue");
  EXPECT_EQ(s[7].value, 1);
  EXPECT_DOUBLE_EQ(s[8].direction.z, -0.5);
  EXPECT_DOUBLE_EQ(s[9].speed, 2);
  EXPECT_EQ(s[11].kind, ScriptCommand::Kind::end);
}

TEST(Script, BadLinesNameTheLine) {
  const auto fails_with = [](const std::string& text, const std::string& fragment) {
    try {
      parse_script(text, "s.txt");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  fails_with("t=0 key=Right\nt=1 key=Nope\n", "s.txt:2: unknown key \"Nope\"");
  fails_with("key=Right\n", "missing time");
  fails_with("t=x key=Right\n", "expected a number");
  fails_with("t=1 key=Right\nt=0.5 key=Left\n", "before the previous");
  fails_with("t=1 jump=3\n", "unknown command");
  fails_with("t=1 snap=1,2\n", "expected snap=X,Y,Z");
  fails_with("t=1 speed=20\n", "outside 0.25 .. 8");
  fails_with("t=1 key=Right key=Left\n", "more than one command");
  fails_with("t=1 axis=iso\n", "axis=NAME:DELTA");
  fails_with("t=1\n", "without a command");
  EXPECT_THROW(read_script("/nonexistent/script.txt"), FileError);
}

TEST(Headless, ScriptedRunShowsTheExpectedStampsAndWritesFramesAndStats) {
  TempDir dir("player-headless");
  const auto db = dir.path / "db";
  testing::write_stamped(db, testing::ring_manifest(4, 2), 10);
  HeadlessOptions o;
  o.script = parse_script(
      "t=0.1 key=Right\n"      // tick 3
      "t=0.2 key=Tab\n"        // tick 6
      "t=0.3 seek=2\n"         // tick 9
      "t=0.4 key=Space\n"      // tick 12: pause
      "t=0.5 key=Left\n"       // tick 15
      "t=0.5 key=Left\n"
      "t=0.6 key=Period\n"     // tick 18
      "t=0.7 end\n");          // 21 ticks shown
  o.frames_out = dir.path / "frames";
  o.stats_out = dir.path / "stats.json";
  const HeadlessResult r = run_headless(db, o);
  ASSERT_EQ(r.frames_displayed, 21);
  EXPECT_EQ(r.placeholders, 0);
  std::vector<Selection> expected;
  int cam = 0, task = 0, frame = 0;
  for (int k = 0; k < 21; ++k) {
    if (k == 3) cam = 1;
    if (k == 6) task = 1;
    if (k == 9) frame = 2;
    if (k == 15) cam = 3;
    if (k == 18) ++frame;
    expected.push_back({cam, task, frame});
    if (k < 12) frame = (frame + 1) % 10;  // playing until the pause at tick 12
  }
  // The pause at tick 12 comes after that tick's clock advance: tick 12 shows frame 5 and so do 13..
  for (int k = 0; k < 21; ++k) {
    EXPECT_EQ(r.shown[std::size_t(k)], expected[std::size_t(k)])
        << "tick " << k << ": shown (" << r.shown[std::size_t(k)].camera << "," << r.shown[std::size_t(k)].task
        << "," << r.shown[std::size_t(k)].frame << ")";
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06d.png", k);
    const auto stamp = read_frame_stamp(read_png((*o.frames_out / name).string()));
    ASSERT_TRUE(stamp.has_value()) << name;
    EXPECT_EQ(*stamp, (FrameStamp{std::uint32_t(expected[std::size_t(k)].camera),
                                  std::uint32_t(expected[std::size_t(k)].task),
                                  std::uint32_t(expected[std::size_t(k)].frame)}))
        << name;
  }
  std::ifstream in(*o.stats_out);
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frames_displayed"], 21);
  EXPECT_EQ(j["displayed"].size(), 21u);
  EXPECT_EQ(j["commands"].size(), 7u);  // `end` ends the run before its tick
  EXPECT_EQ(j["switch_latency"]["count"], 3);  // Right, Tab, Left+Left (one switch: same tick)
  EXPECT_TRUE(j["commands"][0]["applied"].get<bool>());
}

TEST(Script, ReferencesToNothingAreErrorsNotSilentlyIgnored) {
  const store::Manifest m = testing::ring_manifest(4, 2);
  m.validate();
  auto message = [&](const std::string& text) {
    try {
      check_script(parse_script(text), m);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("t=0 camera=3\nt=0.1 task=1\nt=0.2 key=Right\n"), "accepted");
  EXPECT_NE(message("t=0 key=Left\nt=1 camera=999\n").find("line 2: camera 999 does not exist; the database has cameras 0..3"),
            std::string::npos);
  EXPECT_NE(message("t=0 task=nosuch\n").find("no task named \"nosuch\""), std::string::npos);
  EXPECT_NE(message("t=0 task=7\n").find("task 7 does not exist"), std::string::npos);
  EXPECT_NE(message("t=0 axis=nope:+1\n").find("no parameter axis named \"nope\""), std::string::npos);
}

TEST(Headless, DeterministicAcrossRuns) {
  TempDir dir("player-headless-det");
  testing::write_stamped(dir.path, testing::ring_manifest(3, 1), 6);
  HeadlessOptions o;
  o.script = parse_script("t=0.05 key=Right\nt=0.1 speed=2\nt=0.2 key=J\nt=0.4 key=Left\n");
  o.wait_prefetch_each_tick = false;  // shown frames must not depend on prefetch timing
  const auto a = run_headless(dir.path, o);
  const auto b = run_headless(dir.path, o);
  EXPECT_EQ(a.shown, b.shown);
  EXPECT_EQ(a.frames_displayed, 13);  // through t = 0.4 (tick 12)
}

}  // namespace
// Issue 14: walking through a stamped synthetic lattice database while looking around. After each
// walk/look command the shown stream (its stamp) is the lattice neighbour in the direction faced.
TEST(Headless, WalksAndLooksThroughALatticeDatabase) {
  TempDir dir("player-lattice");
  const auto db = dir.path / "db";
  store::SyntheticOptions so;
  so.lattice = {3, 3, 2};
  so.projection = "equirectangular";
  so.width = 64, so.height = 32;
  store::Manifest m = store::synthetic_manifest(so);
  m.video.fps = 30;
  testing::write_stamped(db, m, 2);
  HeadlessOptions o;
  o.engine.start_playing = false;
  o.script = parse_script(
      "t=0.1 walk=forward\n"     // faces +y: node (0,1,0) = 3
      "t=0.2 look=90,0,90\n"     // faces +x
      "t=0.3 walk=forward\n"     // (1,1,0) = 4
      "t=0.4 walk=left\n"        // left of +x is +y: (1,2,0) = 7
      "t=0.5 walk=up\n"          // (1,2,1) = 16
      "t=0.6 look=180,-20,60\n"  // faces -y, a little down
      "t=0.7 walk=forward\n"     // (1,1,1) = 13
      "t=0.8 walk=right\n"       // right of -y is -x: (0,1,1) = 12
      "t=0.9 walk=right\n"       // the lattice ends: stays at 12
      "t=1.0 end\n");
  o.frames_out = dir.path / "frames";
  o.stats_out = dir.path / "stats.json";
  const HeadlessResult r = run_headless(db, o);
  ASSERT_EQ(r.frames_displayed, 30);
  const struct {
    int tick, camera;
    Look look;
  } expect[] = {{0, 0, {0, 0, 90}},    {3, 3, {0, 0, 90}},    {6, 3, {90, 0, 90}},   {9, 4, {90, 0, 90}},
                {12, 7, {90, 0, 90}},  {15, 16, {90, 0, 90}}, {18, 16, {180, -20, 60}}, {21, 13, {180, -20, 60}},
                {24, 12, {180, -20, 60}}, {27, 12, {180, -20, 60}}};
  for (const auto& e : expect)
    for (int k = e.tick; k < e.tick + 3; ++k) {
      EXPECT_EQ(r.shown[std::size_t(k)].camera, e.camera) << "tick " << k;
      EXPECT_NEAR(r.looks[std::size_t(k)].yaw_deg, e.look.yaw_deg, 1e-9) << "tick " << k;
      EXPECT_NEAR(r.looks[std::size_t(k)].pitch_deg, e.look.pitch_deg, 1e-9) << "tick " << k;
      EXPECT_NEAR(r.looks[std::size_t(k)].fov_deg, e.look.fov_deg, 1e-9) << "tick " << k;
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06d.png", k);
      const auto stamp = read_frame_stamp(read_png((*o.frames_out / name).string()));
      ASSERT_TRUE(stamp.has_value()) << name;
      EXPECT_EQ(stamp->camera, std::uint32_t(e.camera)) << name;
    }
  std::ifstream in(*o.stats_out);
  const auto j = nlohmann::json::parse(in);
  EXPECT_FALSE(j["commands"][8]["applied"].get<bool>());  // the walk off the lattice
  EXPECT_EQ(j["displayed"][20]["look"][0].get<double>(), 180.0);
  EXPECT_THROW(parse_script("t=0 walk=sideways\n"), Error);
  EXPECT_THROW(parse_script("t=0 look=0,95,60\n"), Error);
  EXPECT_THROW(parse_script("t=0 look=0,0\n"), Error);
}

}  // namespace panoptes::player
