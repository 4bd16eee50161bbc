#include "player/engine.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.hpp"
#include "core/frame_stamp.hpp"
#include "player/legend.hpp"
#include "player/test_db.hpp"

namespace panoptes::player {
namespace {

using testing::TempDir;

constexpr int kCameras = 6, kTasks = 4, kFrames = 12;

// One stamped database shared by the suite (6 cameras on a ring, 4 tasks = 2 iso x 2 window values).
class EngineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("player-engine");
    testing::write_stamped(dir_->path, testing::ring_manifest(kCameras, kTasks, 64, 64, 2), kFrames);
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static const std::filesystem::path& db() { return dir_->path; }

  // Options for a deterministic engine on the virtual clock.
  EngineOptions opts(bool playing = false, bool prefetch = true) {
    EngineOptions o;
    o.time_source = clock.source();
    o.start_playing = playing;
    o.prefetch = prefetch;
    return o;
  }
  static FrameStamp stamp_of(const ShownFrame& s) {
    const auto st = read_frame_stamp(video::MovieReader::to_rgba(*s.frame));
    EXPECT_TRUE(st.has_value()) << "no stamp in the shown frame";
    return st.value_or(FrameStamp{999, 999, 999});
  }
  static FrameStamp expect(int c, int t, int f) { return {std::uint32_t(c), std::uint32_t(t), std::uint32_t(f)}; }

  VirtualClock clock;
  static TempDir* dir_;
};
TempDir* EngineTest::dir_ = nullptr;

TEST_F(EngineTest, OpensLazilyAndShowsTheStampedFrame) {
  Engine e(db(), opts());
  EXPECT_EQ(e.frame_count(), kFrames);
  EXPECT_DOUBLE_EQ(e.fps(), 30);
  EXPECT_EQ(e.statistics().readers_opened, 0) << "no movie may be opened before a frame is needed";
  const ShownFrame s = e.current_frame();
  EXPECT_EQ(s.status, FrameStatus::ok);
  EXPECT_EQ(s.frame->width, 64);
  EXPECT_EQ(stamp_of(s), expect(0, 0, 0));
  EXPECT_NEAR(s.time, 0.0, 1e-12);
}

TEST_F(EngineTest, EveryCommandShowsTheExpectedStamp) {
  Engine e(db(), opts());
  e.seek(3);
  EXPECT_EQ(stamp_of(e.current_frame()), expect(0, 0, 3));
  ASSERT_TRUE(e.apply(Action::camera_right));
  EXPECT_EQ(stamp_of(e.current_frame()), expect(1, 0, 3));
  ASSERT_TRUE(e.apply(Action::next_task));
  EXPECT_EQ(stamp_of(e.current_frame()), expect(1, 1, 3));
  ASSERT_TRUE(e.apply(Action::frame_forward));
  EXPECT_EQ(stamp_of(e.current_frame()), expect(1, 1, 4));
  ASSERT_TRUE(e.apply(Action::axis_up));  // iso axis: task 1 (iso 0, window 1) -> task 3 (iso 1, window 1)
  EXPECT_EQ(stamp_of(e.current_frame()), expect(1, 3, 4));
  ASSERT_TRUE(e.apply(Action::camera_left));
  ASSERT_TRUE(e.apply(Action::camera_left));  // wraps around the ring
  EXPECT_EQ(stamp_of(e.current_frame()), expect(5, 3, 4));
  ASSERT_TRUE(e.apply(Action::frame_back));
  EXPECT_EQ(stamp_of(e.current_frame()), expect(5, 3, 3));
  ASSERT_TRUE(e.apply(Action::last_frame));
  EXPECT_EQ(stamp_of(e.current_frame()), expect(5, 3, kFrames - 1));
  ASSERT_TRUE(e.apply(Action::task_1));
  ASSERT_TRUE(e.jump_to_camera(2));
  ASSERT_TRUE(e.apply(Action::first_frame));
  EXPECT_EQ(stamp_of(e.current_frame()), expect(2, 0, 0));
  ASSERT_TRUE(e.apply(Action::previous_task));
  EXPECT_EQ(stamp_of(e.current_frame()), expect(2, 3, 0));
  EXPECT_FALSE(e.apply(Action::zoom_in)) << "front-end actions are not the engine's";
  EXPECT_FALSE(e.jump_to_camera(kCameras));
  EXPECT_FALSE(e.jump_to_camera(2)) << "already selected";
  EXPECT_EQ(e.statistics().switches.size(), 6u);  // commands between two shown frames make one switch
}

TEST_F(EngineTest, StepAxisKeepsTheOtherAxis) {
  Engine e(db(), opts());
  ASSERT_EQ(e.manifest().axes.size(), 2u);
  EXPECT_EQ(e.active_axis(), 0);
  ASSERT_TRUE(e.step_axis(1, +1));  // window 0 -> 1, iso stays 0
  EXPECT_EQ(e.selection().task, 1);
  ASSERT_TRUE(e.step_axis(0, +1));  // iso 0 -> 1, window stays 1
  EXPECT_EQ(e.selection().task, 3);
  EXPECT_FALSE(e.step_axis(0, +1)) << "end of the iso axis";
  EXPECT_FALSE(e.step_axis(1, +1)) << "end of the window axis";
  EXPECT_EQ(e.selection().task, 3);
  ASSERT_TRUE(e.apply(Action::next_axis));
  EXPECT_EQ(e.active_axis(), 1);
  ASSERT_TRUE(e.apply(Action::axis_down));
  EXPECT_EQ(e.selection().task, 2);
  EXPECT_FALSE(e.step_axis(5, 1));
  // Shift+A goes back (issue 43), wrapping as A does: 1 -> 0 -> 1.
  ASSERT_TRUE(e.apply(Action::previous_axis));
  EXPECT_EQ(e.active_axis(), 0);
  ASSERT_TRUE(e.apply(Action::previous_axis));
  EXPECT_EQ(e.active_axis(), 1);
  EXPECT_EQ(e.selection().task, 2) << "changing the active axis changes no task";
}

TEST_F(EngineTest, PlaybackClockAndSwitchingKeepTimeContinuous) {
  Engine e(db(), opts(/*playing=*/true));
  e.set_loop(true);
  for (int k = 0; k < 3 * kFrames; ++k) {
    clock.set(k / 30.0);
    e.tick();
    if (k % 5 == 2) e.apply(Action::camera_right);  // switch while playing
    if (k % 7 == 3) e.apply(Action::next_task);
    const ShownFrame s = e.current_frame();
    const FrameStamp st = stamp_of(s);
    ASSERT_EQ(st.frame, std::uint32_t(k % kFrames)) << "tick " << k << ": a frame was repeated or skipped";
    ASSERT_EQ(st.camera, std::uint32_t(e.selection().camera));
    ASSERT_EQ(st.task, std::uint32_t(e.selection().task));
  }
}

TEST_F(EngineTest, SpeedDirectionLoopAndPause) {
  Engine e(db(), opts(true));
  e.set_speed(2);
  clock.set(3 / 30.0);
  e.tick();
  EXPECT_EQ(e.selection().frame, 6);
  e.set_speed(100);
  EXPECT_DOUBLE_EQ(e.speed(), 8);
  e.set_speed(0.25);
  clock.set(3 / 30.0 + 8 / 30.0);  // 8 ticks at x1/4 = 2 frames
  e.tick();
  EXPECT_EQ(e.selection().frame, 8);
  e.set_speed(1);
  e.set_direction(-1);
  clock.advance(3 / 30.0);
  e.tick();
  EXPECT_EQ(e.selection().frame, 5);
  e.set_playing(false);
  clock.advance(1.0);
  e.tick();
  EXPECT_EQ(e.selection().frame, 5) << "paused: the clock must not move";
  // Backward past 0 without loop: stops at 0 and pauses.
  e.set_loop(false);
  e.set_playing(true);
  clock.advance(1.0);
  e.tick();
  EXPECT_EQ(e.selection().frame, 0);
  EXPECT_FALSE(e.playing());
  // Forward past the end with loop: wraps.
  e.set_direction(1);
  e.set_loop(true);
  e.seek(kFrames - 1);
  e.set_playing(true);
  clock.advance(2 / 30.0);
  e.tick();
  EXPECT_EQ(e.selection().frame, 1);
}

TEST_F(EngineTest, PlayAtTheEndWithoutLoopRestarts) {
  Engine e(db(), opts(true));
  e.set_loop(false);
  clock.set(100.0);
  e.tick();
  EXPECT_EQ(e.selection().frame, kFrames - 1);
  EXPECT_FALSE(e.playing());
  ASSERT_TRUE(e.apply(Action::play_pause));
  EXPECT_EQ(e.selection().frame, 0);
  clock.advance(2 / 30.0);
  e.tick();
  EXPECT_EQ(e.selection().frame, 2);
}

TEST_F(EngineTest, NearestCameraAndSnap) {
  Engine e(db(), opts());
  // Ring cameras at longitudes 0, 60, ..., 300 degrees.
  EXPECT_EQ(e.nearest_camera({1, 0, 0}), 0);
  EXPECT_EQ(e.nearest_camera({std::cos(1.1), std::sin(1.1), 0.3}), 1);
  EXPECT_EQ(e.nearest_camera({-1, -0.1, 0}), 3);
  EXPECT_EQ(e.nearest_camera({0, 0, 0}), -1);
  ASSERT_TRUE(e.snap_to_direction({std::cos(-1.0), std::sin(-1.0), 0}));
  EXPECT_EQ(e.selection().camera, 5);
  EXPECT_FALSE(e.snap_to_direction({std::cos(-1.0), std::sin(-1.0), 0})) << "already there";
  EXPECT_EQ(e.statistics().switches.size(), 0u) << "no frame shown yet, so no switch completed";
  e.current_frame();
  EXPECT_EQ(e.statistics().switches.size(), 1u);
  EXPECT_EQ(e.statistics().switches[0].command, "snap");
}

TEST_F(EngineTest, PrefetchMakesASwitchHitTheCache) {
  Engine e(db(), opts());
  e.seek(4);
  EXPECT_FALSE(e.current_frame().cache_hit);
  e.wait_prefetch_idle();
  EXPECT_TRUE(e.is_cached({1, 0, 4}));
  EXPECT_TRUE(e.is_cached({5, 0, 4}));
  EXPECT_TRUE(e.is_cached({0, 1, 4}));
  EXPECT_TRUE(e.is_cached({0, 2, 5})) << "task-axis neighbour at the next frame";
  ASSERT_TRUE(e.apply(Action::camera_right));
  const ShownFrame s = e.current_frame();
  EXPECT_TRUE(s.cache_hit);
  EXPECT_EQ(stamp_of(s), expect(1, 0, 4));
  const auto st = e.statistics();
  ASSERT_EQ(st.switches.size(), 1u);
  EXPECT_TRUE(st.switches[0].cache_hit);
  EXPECT_GT(st.prefetch_decodes, 0);
}

// The prefetch queue's order is what decides a switch under load (issue 14: paused walks through
// 1920x960 360° streams missed because the neighbours' current frame came after 9 other decodes).
TEST_F(EngineTest, PrefetchPlanPutsWhatASwitchShowsFirst) {
  Engine e(db(), opts());
  e.seek(4);
  const auto is_neighbour = [](const Selection& s) { return !(s.camera == 0 && s.task == 0); };
  // Paused: a switch shows a neighbour's frame 4, so every neighbour at frame 4 comes before anything else.
  std::vector<Selection> plan = e.prefetch_plan();
  ASSERT_GE(plan.size(), 5u);
  std::size_t first_other = 0;
  while (first_other < plan.size() && plan[first_other].frame == 4 && is_neighbour(plan[first_other])) ++first_other;
  EXPECT_EQ(first_other, 5u) << "cameras 1 and 5, tasks 1 and 3 (next/previous), task 2 (the window axis)";
  EXPECT_EQ(plan[first_other], (Selection{0, 0, 5})) << "then the current stream's next frame";
  // Playing: the current stream's next frame, then every neighbour at that frame.
  e.set_playing(true);
  plan = e.prefetch_plan();
  EXPECT_EQ(plan[0], (Selection{0, 0, 5}));
  for (std::size_t i = 1; i <= 5; ++i) EXPECT_TRUE(plan[i].frame == 5 && is_neighbour(plan[i])) << "entry " << i;
  e.set_playing(false);
  // A view hint towards camera 5 ranks it first; towards camera 1, that one.
  const auto& cams = e.manifest().cameras;
  e.set_view_direction(cams[5].position - cams[0].position);
  EXPECT_EQ(e.prefetch_plan()[0], (Selection{5, 0, 4}));
  e.set_view_direction(cams[1].position - cams[0].position);
  EXPECT_EQ(e.prefetch_plan()[0], (Selection{1, 0, 4}));
  e.set_view_direction({0, 0, 0});  // cleared: graph order (left = 5 first)
  EXPECT_EQ(e.prefetch_plan()[0], (Selection{5, 0, 4}));
}

TEST_F(EngineTest, PrefetchDuringPlaybackServesTheNextFrameOfANeighbour) {
  Engine e(db(), opts(true));
  for (int k = 0; k < 8; ++k) {
    e.wait_prefetch_idle();  // the display period the prefetch threads get
    clock.set(k / 30.0);
    e.tick();
    if (k == 5) e.apply(Action::camera_left);
    const ShownFrame s = e.current_frame();
    if (k >= 1) {
      EXPECT_TRUE(s.cache_hit) << "tick " << k;
    }
  }
  const auto st = e.statistics();
  ASSERT_EQ(st.switches.size(), 1u);
  EXPECT_TRUE(st.switches[0].cache_hit);
}

TEST_F(EngineTest, WithoutPrefetchASwitchDecodesOnTheDisplayPath) {
  Engine e(db(), opts(false, /*prefetch=*/false));
  e.current_frame();
  e.wait_prefetch_idle();
  ASSERT_TRUE(e.apply(Action::camera_right));
  EXPECT_FALSE(e.current_frame().cache_hit);
  EXPECT_EQ(e.statistics().prefetch_decodes, 0);
  EXPECT_EQ(e.statistics().display_decodes, 2);
}

TEST_F(EngineTest, ReaderPoolBoundIsRespected) {
  EngineOptions o = opts(true);
  o.reader_pool_capacity = 3;
  o.prefetch_threads = 1;
  Engine e(db(), o);
  for (int k = 0; k < 30; ++k) {
    clock.set(k / 30.0);
    e.tick();
    e.apply(k % 2 ? Action::camera_right : Action::next_task);
    EXPECT_EQ(e.current_frame().status, FrameStatus::ok);
    ASSERT_LE(e.statistics().readers_open, 3);
  }
  e.wait_prefetch_idle();
  const auto st = e.statistics();
  EXPECT_LE(st.readers_open, 3);
  EXPECT_GT(st.readers_evicted, 0);
  EXPECT_THROW(Engine(db(), [&] { auto x = o; x.reader_pool_capacity = 2; return x; }()), Error);
  EXPECT_THROW(Engine(db(), [&] { auto x = o; x.prefetch_nice = 20; return x; }()), Error);
  EXPECT_THROW(Engine(db(), [&] { auto x = o; x.prefetch_nice = -1; return x; }()), Error);
}

TEST_F(EngineTest, FrameCacheCapIsRespected) {
  EngineOptions o = opts(true);
  const std::size_t frame = 64 * 64 * 3 / 2 + 200;
  o.cache_bytes = 6 * frame;
  Engine e(db(), o);
  for (int k = 0; k < 24; ++k) {
    clock.set(k / 30.0);
    e.tick();
    if (k % 3 == 0) e.apply(Action::camera_right);
    EXPECT_EQ(stamp_of(e.current_frame()).frame, std::uint32_t(k % kFrames));
    e.wait_prefetch_idle();
    ASSERT_LE(e.statistics().cache_bytes, o.cache_bytes);
  }
  EXPECT_GT(e.statistics().cache_evictions, 0);
  EXPECT_EQ(e.statistics().cache_capacity, o.cache_bytes);
}

TEST_F(EngineTest, StatisticsJson) {
  Engine e(db(), opts());
  e.current_frame();
  e.apply(Action::camera_right);
  e.current_frame();
  TempDir out("player-stats");
  e.write_statistics(out.path / "s.json");
  std::ifstream in(out.path / "s.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frames_shown"], 2);
  EXPECT_EQ(j["switch_latency"]["count"], 1);
  EXPECT_EQ(j["switches"][0]["command"], "camera_right");
  EXPECT_GE(j["decode_time"]["count"].get<int>(), 1);
  EXPECT_THROW(e.write_statistics("/nonexistent-dir/x/s.json"), FileError);
}

TEST(Summary, Percentiles) {
  std::vector<double> v;
  for (int i = 1; i <= 100; ++i) v.push_back(i);
  const Summary s = summarize(v);
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.p50, 50);
  EXPECT_DOUBLE_EQ(s.p99, 99);
  EXPECT_DOUBLE_EQ(s.max, 100);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_EQ(summarize({}).count, 0u);
}

// ---- broken databases: each test writes its own small database ----

class BrokenDbTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::write_stamped(dir.path, testing::ring_manifest(4, 1), 8);
  }
  EngineOptions opts() {
    EngineOptions o;
    o.time_source = clock.source();
    return o;
  }
  std::filesystem::path movie(int c, int t) { return store::Database::open(dir.path).stream_path(c, t); }
  TempDir dir{"player-broken"};
  VirtualClock clock;
};

// Plays 16 ticks, moving right every 4; returns the status of every shown frame and checks that the
// clock kept going and good streams showed their stamps.
std::vector<FrameStatus> play_around(Engine& e, VirtualClock& clock) {
  std::vector<FrameStatus> statuses;
  for (int k = 0; k < 16; ++k) {
    clock.set(k / 30.0);
    e.tick();
    if (k % 4 == 0 && k > 0) e.apply(Action::camera_right);
    const ShownFrame s = e.current_frame();
    EXPECT_EQ(s.selection.frame, k % 8) << "playback must continue through broken streams";
    EXPECT_TRUE(s.frame);
    EXPECT_EQ(s.frame->width, 64);
    const auto stamp = read_frame_stamp(video::MovieReader::to_rgba(*s.frame));
    if (s.status == FrameStatus::ok) {
      EXPECT_EQ(stamp, (FrameStamp{std::uint32_t(s.selection.camera), 0, std::uint32_t(k % 8)}));
    } else {
      EXPECT_FALSE(stamp.has_value()) << "a placeholder must not look like data";
      EXPECT_FALSE(s.message.empty());
    }
    statuses.push_back(s.status);
  }
  return statuses;
}

TEST_F(BrokenDbTest, MissingMovieShowsPlaceholderAndPlaybackContinues) {
  std::filesystem::remove(movie(1, 0));
  Engine e(dir.path, opts());
  const auto st = play_around(e, clock);
  for (int k = 0; k < 16; ++k)
    EXPECT_EQ(st[std::size_t(k)], k >= 4 && k < 8 ? FrameStatus::missing : FrameStatus::ok) << "tick " << k;
  EXPECT_EQ(e.statistics().placeholders_shown, 4);
}

TEST_F(BrokenDbTest, CorruptMovieShowsPlaceholder) {
  {
    std::ofstream f(movie(2, 0), std::ios::binary | std::ios::trunc);
    for (int i = 0; i < 5000; ++i) f.put(char((i * 7919) & 0xff));
  }
  Engine e(dir.path, opts());
  const auto st = play_around(e, clock);
  for (int k = 0; k < 16; ++k)
    EXPECT_EQ(st[std::size_t(k)], k >= 8 && k < 12 ? FrameStatus::unreadable : FrameStatus::ok) << "tick " << k;
}

TEST_F(BrokenDbTest, TruncatedMovieShowsWhatItHasThenPlaceholder) {
  const auto path = movie(1, 0);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  Engine e(dir.path, opts());
  const auto st = play_around(e, clock);
  for (int k = 0; k < 16; ++k)
    if (k < 4 || k >= 8) {
      EXPECT_EQ(st[std::size_t(k)], FrameStatus::ok) << "tick " << k;
    }
  EXPECT_NE(st[7], FrameStatus::ok) << "the second half of the movie is gone";
}

TEST_F(BrokenDbTest, PlaceholderSaysWhatIsWrong) {
  const auto p = make_placeholder(200, 120, "STREAM MISSING", "CAMERA 3 TASK 1");
  EXPECT_EQ(p.width, 200);
  EXPECT_EQ(p.y.size(), 200u * 120u);
  EXPECT_EQ(p.u.size(), 100u * 60u);
  int bright = 0;
  for (auto v : p.y) bright += v > 200;
  EXPECT_GT(bright, 200) << "the text must be drawn";
  const auto odd = make_placeholder(63, 31, "STREAM UNREADABLE", "x");
  EXPECT_EQ(odd.u.size(), 32u * 16u);
}

TEST(InterruptedDb, PlaysTheFramesItHas) {
  TempDir dir("player-interrupted");
  const auto m = testing::ring_manifest(2, 1);
  {
    auto w = store::DatabaseWriter::create(dir.path, m, true);
    for (int f = 0; f < 5; ++f)
      for (int c = 0; c < 2; ++c) w.append(c, 0, testing::stamped_frame(c, 0, f, 64, 64));
    w.checkpoint();
    for (int c = 0; c < 2; ++c) w.append(c, 0, testing::stamped_frame(c, 0, 5, 64, 64));
  }  // destroyed without finalize: the run was "killed"
  const auto db = store::Database::open(dir.path);
  ASSERT_EQ(db.status(), store::Status::interrupted);
  VirtualClock clock;
  EngineOptions o;
  o.time_source = clock.source();
  Engine e(db, o);
  ASSERT_GE(e.frame_count(), 5);
  for (int k = 0; k < 2 * e.frame_count(); ++k) {
    clock.set(k / 30.0);
    e.tick();
    const ShownFrame s = e.current_frame();
    ASSERT_EQ(s.status, FrameStatus::ok) << s.message;
    EXPECT_EQ(s.selection.frame, k % e.frame_count());
  }
}

TEST(LiveDb, RefreshTakesOverNewCheckpoints) {
  TempDir dir("player-live");
  const auto m = testing::ring_manifest(2, 1);
  auto w = store::DatabaseWriter::create(dir.path, m, true);
  const auto write = [&](int from, int to) {
    for (int f = from; f < to; ++f)
      for (int c = 0; c < 2; ++c) w.append(c, 0, testing::stamped_frame(c, 0, f, 64, 64));
    w.checkpoint();
  };
  write(0, 3);
  VirtualClock clock;
  EngineOptions o;
  o.time_source = clock.source();
  o.start_playing = false;
  Engine e(dir.path, o);
  EXPECT_EQ(e.status(), store::Status::running);
  EXPECT_EQ(e.frame_count(), 3);
  e.seek(2);
  EXPECT_EQ(e.current_frame().status, FrameStatus::ok);  // readers are open now, indexing 3 frames
  e.wait_prefetch_idle();
  write(3, 7);
  EXPECT_EQ(e.frame_count(), 3) << "nothing changes until refresh()";
  EXPECT_EQ(e.refresh(), 7);
  e.seek(6);
  const ShownFrame s = e.current_frame();
  ASSERT_EQ(s.status, FrameStatus::ok) << s.message;
  EXPECT_EQ(read_frame_stamp(video::MovieReader::to_rgba(*s.frame)), (FrameStamp{0, 0, 6}));
  w.finalize();
  e.refresh();
  EXPECT_EQ(e.status(), store::Status::complete);
}

// Issue 41.3: a window opened while the run is still writing (scripts/demo with a display) kept frame 0's
// reference: at frame 9 the legend read 0..6.90e-07 where that frame recorded 1.13e-04. The manifest the
// front ends read per frame (live_manifest) must follow the database as it grows, and after a seek.
TEST(LiveDb, TheLegendFollowsTheReferencesOfFramesWrittenAfterOpening) {
  TempDir dir("player-live-legend");
  auto m = testing::ring_manifest(2, 1);
  m.fields = {{"phi_p", "1/s", {}, ""}};
  m.tasks[0].method = "slice";
  m.tasks[0].fields = {"phi_p"};
  m.tasks[0].parameters = {{"window", {-1.0, 1.0}}, {"relative", true}};
  auto w = store::DatabaseWriter::create(dir.path, m, true);
  const auto reference = [](int f) { return 6.9e-7 * std::pow(2.0, f); };  // grows as a wave front does
  const auto write = [&](int from, int to) {
    for (int f = from; f < to; ++f) {
      for (int c = 0; c < 2; ++c) w.append(c, 0, testing::stamped_frame(c, 0, f, 64, 64));
      w.set_field_reference(f, 0, reference(f));
    }
    w.checkpoint();
  };
  write(0, 1);
  VirtualClock clock;
  EngineOptions o;
  o.time_source = clock.source();
  o.start_playing = false;
  Engine e(dir.path, o);
  ASSERT_EQ(e.frame_count(), 1);
  write(1, 10);
  clock.advance(2 * o.refresh_seconds);
  e.tick();  // a running database is re-read on the playback clock
  ASSERT_EQ(e.frame_count(), 10);
  for (const int f : {9, 4}) {
    e.seek(f);
    ASSERT_EQ(e.selection().frame, f);
    const auto bars = task_legend(*e.live_manifest(), 0, e.selection().frame);
    ASSERT_EQ(bars.size(), 1u);
    EXPECT_DOUBLE_EQ(bars[0].hi, reference(f)) << "frame " << f << ": " << legend_range_text(bars[0]);
    EXPECT_DOUBLE_EQ(bars[0].lo, -reference(f));
  }
  // A pointer taken before a refresh stays valid (the HUD holds one for the frame it draws).
  const auto held = e.live_manifest();
  write(10, 12);
  clock.advance(2 * o.refresh_seconds);
  e.tick();
  EXPECT_EQ(e.frame_count(), 12);
  EXPECT_EQ(held->fields[0].references.size(), 10u);
  EXPECT_EQ(e.live_manifest()->fields[0].references.size(), 12u);
  EXPECT_EQ(e.manifest().fields[0].references.size(), 1u) << "manifest() stays the one read at opening";
  w.finalize();
}

TEST(LiveDb, TickRefreshesARunningDatabase) {
  TempDir dir("player-live-tick");
  const auto m = testing::ring_manifest(2, 1);
  auto w = store::DatabaseWriter::create(dir.path, m, true);
  const auto write = [&](int from, int to) {
    for (int f = from; f < to; ++f)
      for (int c = 0; c < 2; ++c) w.append(c, 0, testing::stamped_frame(c, 0, f, 64, 64));
    w.checkpoint();
  };
  write(0, 3);
  VirtualClock clock;
  EngineOptions o;
  o.time_source = clock.source();
  o.start_playing = false;
  o.refresh_seconds = 1.0;
  Engine e(dir.path, o);
  clock.set(0.5);
  e.tick();
  write(3, 5);
  clock.set(0.9);
  e.tick();
  EXPECT_EQ(e.frame_count(), 3) << "refreshed before refresh_seconds passed";
  clock.set(1.6);
  e.tick();
  EXPECT_EQ(e.frame_count(), 5) << "the new frames of a running database did not appear";
  w.finalize();
  clock.set(3.0);
  e.tick();
  EXPECT_EQ(e.status(), store::Status::complete);
}

TEST(DamagedMovie, ConcealedFramesShowAPlaceholderNeverAnotherFrame) {
  TempDir dir("player-damaged");
  auto m = testing::ring_manifest(1, 1);
  m.video.gop = 30;
  {
    auto w = store::DatabaseWriter::create(dir.path, m, true);
    for (int f = 0; f < 30; ++f) w.append(0, 0, testing::stamped_frame(0, 0, f, 64, 64));
    w.finalize();
  }
  // Zero a run of bytes in the middle of the coded pictures: the decoder notices and conceals.
  const auto path = dir.path / "movies/c0/t0.mp4";
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto mdat = bytes.find("mdat");
  ASSERT_NE(mdat, std::string::npos);
  const std::size_t at = mdat + (bytes.size() - mdat) / 2;
  for (std::size_t i = at; i < at + 24 && i < bytes.size(); ++i) bytes[i] = 0;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << bytes;
  }
  VirtualClock clock;
  EngineOptions o;
  o.time_source = clock.source();
  o.start_playing = false;
  Engine e(dir.path, o);
  int damaged = 0;
  for (int f = 0; f < e.frame_count(); ++f) {
    e.seek(f);
    const ShownFrame s = e.current_frame();
    if (s.status == FrameStatus::ok) {
      EXPECT_EQ(read_frame_stamp(video::MovieReader::to_rgba(*s.frame)), (FrameStamp{0, 0, std::uint32_t(f)}))
          << "frame " << f << " shown with another frame's content";
    } else {
      EXPECT_EQ(s.status, FrameStatus::damaged) << s.message;
      EXPECT_NE(s.message.find("damaged"), std::string::npos) << s.message;
      ++damaged;
    }
  }
  EXPECT_GT(damaged, 0) << "the concealed frames were shown as ok";
}

TEST(DamagedMovie, AnotherStreamsMovieShowsAPlaceholderNeverItsFrames) {
  // Issue #31 row 6: camera 1's movie copied over camera 0's played as camera 0, every frame "ok".
  TempDir dir("player-foreign");
  auto m = testing::ring_manifest(2, 1);
  m.video.gop = 1;
  {
    auto w = store::DatabaseWriter::create(dir.path, m, true);
    for (int f = 0; f < 4; ++f)
      for (int c = 0; c < 2; ++c) w.append(c, 0, testing::stamped_frame(c, 0, f, 64, 64));
    w.finalize();
  }
  std::filesystem::copy_file(dir.path / "movies/c1/t0.mp4", dir.path / "movies/c0/t0.mp4",
                             std::filesystem::copy_options::overwrite_existing);
  VirtualClock clock;
  EngineOptions o;
  o.time_source = clock.source();
  o.start_playing = false;
  Engine e(dir.path, o);
  ASSERT_EQ(e.selection().camera, 0);
  for (int f = 0; f < e.frame_count(); ++f) {
    e.seek(f);
    const ShownFrame s = e.current_frame();
    EXPECT_EQ(s.status, FrameStatus::damaged) << "frame " << f << ": " << s.message;
    EXPECT_NE(s.message.find("another movie"), std::string::npos) << s.message;
  }
}

TEST(EngineErrors, ClearErrorsForBadInput) {
  EXPECT_THROW(Engine("/nonexistent/db"), FileError);
  TempDir dir("player-empty");
  auto w = store::DatabaseWriter::create(dir.path, testing::ring_manifest(2, 1), true);
  w.checkpoint();  // a live writer, no frame yet
  try {
    Engine e(dir.path);
    FAIL() << "an empty database must be refused";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("no complete frame"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace panoptes::player

namespace panoptes::player {
namespace {

// A rig with two patches and two shells, like a Yin-Yang seam: the graph's edges, not geometry,
// decide where a key goes — including asymmetric seam edges, poles without an `up`, and shell links.
TEST(Navigation, FollowsTheGraphAcrossSeamsPolesAndShells) {
  TempDir dir("player-seam");
  store::Manifest m = testing::ring_manifest(6, 1);
  // cameras 0..2 = patch A (outer shell), 3..5 = patch B; camera 5 is an inner-shell camera.
  auto& g = m.graph.neighbours;
  g[0] = {.left = 2, .right = 1, .up = 3, .down = -1, .in = 5, .out = -1};  // pole: no down
  g[1] = {.left = 0, .right = 2, .up = 4, .down = -1, .in = -1, .out = -1};
  g[2] = {.left = 1, .right = 0, .up = 3, .down = -1, .in = -1, .out = -1};  // seam: up goes to B's 3 too
  g[3] = {.left = 4, .right = 4, .up = -1, .down = 2, .in = -1, .out = -1};  // asymmetric: 3.down = 2, 0.up = 3
  g[4] = {.left = 3, .right = 3, .up = -1, .down = 1, .in = -1, .out = -1};
  g[5] = {.left = -1, .right = -1, .up = -1, .down = -1, .in = -1, .out = 0};
  m.cameras[5].labels.shell = 1;
  testing::write_stamped(dir.path, m, 3);
  EngineOptions o;
  o.start_playing = false;
  o.prefetch = false;
  Engine e(dir.path, o);
  const auto go = [&](Action a) {
    const bool moved = e.apply(a);
    const auto s = read_frame_stamp(video::MovieReader::to_rgba(*e.current_frame().frame));
    EXPECT_TRUE(s.has_value());
    EXPECT_EQ(s ? int(s->camera) : -1, e.selection().camera);
    return moved;
  };
  EXPECT_FALSE(go(Action::camera_down));  // pole
  EXPECT_EQ(e.selection().camera, 0);
  EXPECT_TRUE(go(Action::camera_left));   // wrap-around
  EXPECT_EQ(e.selection().camera, 2);
  EXPECT_TRUE(go(Action::camera_up));     // across the seam
  EXPECT_EQ(e.selection().camera, 3);
  EXPECT_TRUE(go(Action::camera_down));   // back over the seam, but to 2 (the edge says so)
  EXPECT_EQ(e.selection().camera, 2);
  EXPECT_TRUE(go(Action::camera_right));
  EXPECT_EQ(e.selection().camera, 0);
  EXPECT_TRUE(go(Action::shell_in));
  EXPECT_EQ(e.selection().camera, 5);
  EXPECT_FALSE(go(Action::shell_in));
  EXPECT_FALSE(go(Action::camera_right));
  EXPECT_TRUE(go(Action::shell_out));
  EXPECT_EQ(e.selection().camera, 0);
  // Snapping keeps to the current shell: camera 5 sits on the ring at 300°, but 0 is on shell 0.
  EXPECT_EQ(e.nearest_camera({std::cos(-1.0), std::sin(-1.0), 0}, 0), 0);
  EXPECT_EQ(e.nearest_camera({std::cos(-1.0), std::sin(-1.0), 0}), 5);
}

// Issue 34: the opposite arrow key retraces the last moves even where the graph's edges are not
// mutual (around a pole several cameras share the camera above them), and a jump starts afresh.
TEST(Navigation, TheOppositeKeyRetracesTheLastMoves) {
  TempDir dir("player-retrace");
  store::Manifest m = testing::ring_manifest(6, 1);
  auto& g = m.graph.neighbours;
  g[0] = {.left = 2, .right = 1, .up = 3, .down = -1, .in = -1, .out = -1};
  g[1] = {.left = 0, .right = 2, .up = 3, .down = -1, .in = -1, .out = -1};
  g[2] = {.left = 1, .right = 0, .up = 3, .down = -1, .in = -1, .out = -1};
  g[3] = {.left = 4, .right = 5, .up = 4, .down = 2, .in = -1, .out = -1};  // one down for three cameras below
  g[4] = {.left = 3, .right = 3, .up = 5, .down = 1, .in = -1, .out = -1};
  g[5] = {.left = 4, .right = 3, .up = 3, .down = 4, .in = -1, .out = -1};
  testing::write_stamped(dir.path, m, 3);
  EngineOptions o;
  o.start_playing = false;
  o.prefetch = false;
  Engine e(dir.path, o);
  const auto camera_after = [&](std::initializer_list<Action> keys) {
    for (Action a : keys) e.apply(a);
    return e.selection().camera;
  };
  // Up, Up, Down, Down from 0: 0 -> 3 -> 4 -> 3 -> 0 (the graph alone: 3 -> 4 -> 1 -> -1).
  EXPECT_EQ(camera_after({Action::camera_up, Action::camera_up}), 4);
  EXPECT_EQ(camera_after({Action::camera_down}), 3);
  EXPECT_EQ(camera_after({Action::camera_down}), 0);
  // Down again follows the graph (pole: no move), Left then Right returns.
  EXPECT_EQ(camera_after({Action::camera_down}), 0);
  EXPECT_EQ(camera_after({Action::camera_left, Action::camera_right}), 0);
  // From 1: Up then Down returns to 1, though 3's Down is 2.
  ASSERT_TRUE(e.jump_to_camera(1));
  EXPECT_EQ(camera_after({Action::camera_up, Action::camera_down}), 1);
  // A jump in between forgets the trail: Down from 3 then follows the graph.
  EXPECT_EQ(camera_after({Action::camera_up}), 3);
  ASSERT_TRUE(e.jump_to_camera(5));
  ASSERT_TRUE(e.jump_to_camera(3));
  EXPECT_EQ(camera_after({Action::camera_down}), 2);
}

}  // namespace
}  // namespace panoptes::player
