// [output] mode (issue 28): "create" refuses an existing database naming the key, "overwrite"
// replaces it, "resume" continues one after a restart: a run SIGKILLed in the middle of a snapshot
// and restarted from an earlier step equals the uninterrupted run frame for frame.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "insitu/session.hpp"
#include "render/synthetic_fields.hpp"
#include "store/database.hpp"

using namespace panoptes;
namespace fs = std::filesystem;

namespace {

std::string resume_error_of(const std::string& toml) {
  try {
    (void)insitu::parse_session_config_text(toml + "[[task]]\nname = \"v\"\nfield = \"f\"\n", "test.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(InsituOutputMode, KeyAndItsOldSpelling) {
  auto mode = [](const std::string& output) {
    return insitu::parse_session_config_text("[output]\n" + output + "\n[[task]]\nname = \"v\"\nfield = \"f\"\n", "t").mode;
  };
  EXPECT_EQ(mode(""), insitu::OutputMode::create);
  EXPECT_EQ(mode("mode = \"resume\""), insitu::OutputMode::resume);
  EXPECT_EQ(mode("mode = \"overwrite\""), insitu::OutputMode::overwrite);
  EXPECT_EQ(mode("overwrite = true"), insitu::OutputMode::overwrite);
  EXPECT_EQ(mode("overwrite = false"), insitu::OutputMode::create);
  const std::string bad = resume_error_of("[output]\nmode = \"append\"\n");
  EXPECT_NE(bad.find("output.mode"), std::string::npos) << bad;
  EXPECT_NE(bad.find("\"resume\""), std::string::npos) << bad;
  const std::string both = resume_error_of("[output]\nmode = \"resume\"\noverwrite = true\n");
  EXPECT_NE(both.find("give only [output] mode"), std::string::npos) << both;
}

const char* kConfig = R"(
[image]
width = 32
height = 30
[rig]
spec = "fibonacci:4"
[schedule]
every_steps = 1
[render]
reference = "running-max"
[[task]]
name = "v"
field = "f"
[[task]]
name = "iso"
type = "isosurface"
field = "f"
isovalues = [0.2, 0.5]
relative = true
)";

insitu::SessionConfig config(const fs::path& dir, insitu::OutputMode mode) {
  insitu::SessionConfig c = insitu::parse_session_config_text(kConfig, "resume config");
  c.output_dir = dir.string();
  c.mode = mode;
  return c;
}

render::GridGeometry test_grid() { return {{20, 18, 16}, {0, 0, 0}, {1, 1, 1}}; }

std::vector<float> resume_field(double t) {
  const render::GridGeometry g = test_grid();
  // A wave that grows until the last snapshot before the kill (t = 0.4) and then fades: the frames
  // after the restart depend on the running reference kept across it.
  const double amp = t <= 0.4 ? 1.0 + t : 1.4 - 0.8 * (t - 0.4);
  const std::vector<render::WaveFront> fronts{{g.centre(), 3 + 2 * t, 1.5, float(amp)}};
  return render::wave_field(g, fronts);
}

constexpr int kSteps = 6;
double time_of(int step) { return 0.2 * step; }

// Steps first..kSteps-1 of the simulation; `kill_in` ≥ 0: SIGKILL in the middle of that snapshot.
void run(const fs::path& dir, insitu::OutputMode mode, int first, int kill_in = -1) {
  insitu::Session s(config(dir, mode), test_grid(), insitu::LocalBlock::whole(test_grid()));
  if (kill_in >= 0)
    s.set_frame_observer([kill_in](int camera, int, int frame, const Image&) {
      if (frame == kill_in && camera == 2) ::raise(SIGKILL);
    });
  for (int step = first; step < kSteps; ++step) {
    const auto f = resume_field(time_of(step));
    s.process(step, time_of(step), {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }
  s.finalize();
}

TEST(InsituResume, KilledRunResumedEqualsTheUninterruptedRun) {
  // The killed run is a re-executed copy of this binary (see KilledRunOpensInterrupted in
  // session_test.cpp: libgomp is not fork-safe); it finds its directory through the environment.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  if (!std::getenv("PANOPTES_TEST_RESUME_DIR")) {
    const fs::path d = fs::temp_directory_path() / ("insitu_resume_" + std::to_string(::getpid()));
    ::setenv("PANOPTES_TEST_RESUME_DIR", d.c_str(), 1);
  }
  const fs::path base = std::getenv("PANOPTES_TEST_RESUME_DIR");
  const fs::path full = base / "full", killed = base / "killed";
  fs::remove_all(base);
  fs::create_directories(base);
  run(full, insitu::OutputMode::create, 0);
  EXPECT_EXIT(run(killed, insitu::OutputMode::create, 0, 3), ::testing::KilledBySignal(SIGKILL), "");
  {
    const auto db = store::Database::open(killed);
    ASSERT_EQ(db.status(), store::Status::interrupted);
    ASSERT_EQ(db.frame_count(), 3);  // snapshots 0, 1, 2 checkpointed; 3 died half-way
  }
  // Without resume the directory is refused, naming the key a C, Fortran or Python user has.
  try {
    run(killed, insitu::OutputMode::create, 2);
    ADD_FAILURE() << "an existing database was accepted in mode create";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("[output] mode"), std::string::npos) << m;
    EXPECT_EQ(m.find("--overwrite"), std::string::npos) << m;
    EXPECT_EQ(m.find("WriterOptions"), std::string::npos) << m;
  }
  // The simulation restarts from its checkpoint at step 2: snapshot 2 is repeated (skipped), 3..5 new.
  run(killed, insitu::OutputMode::resume, 2);
  const auto a = store::Database::open(full), b = store::Database::open(killed);
  ASSERT_EQ(b.status(), store::Status::complete);
  ASSERT_EQ(b.frame_count(), kSteps);
  ASSERT_EQ(b.manifest().times.size(), std::size_t(kSteps));
  for (int f = 0; f < kSteps; ++f) EXPECT_DOUBLE_EQ(b.manifest().times[std::size_t(f)], time_of(f));
  int frames = 0;
  for (int c = 0; c < a.camera_count(); ++c)
    for (int t = 0; t < a.task_count(); ++t) {
      auto ra = a.stream(c, t), rb = b.stream(c, t);
      ASSERT_EQ(rb->frame_count(), kSteps) << "camera " << c << " task " << t;  // nothing duplicated
      for (int f = 0; f < kSteps; ++f, ++frames)
        ASSERT_EQ(ra->read_rgba(f).pixels, rb->read_rgba(f).pixels) << "camera " << c << " task " << t << " frame " << f;
    }
  EXPECT_EQ(frames, 4 * 3 * kSteps);
  fs::remove_all(base);
}

TEST(InsituResume, RefusesAnotherConfigurationNamingWhatDiffers) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_resume_cfg_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  {
    insitu::Session s(config(dir, insitu::OutputMode::create), test_grid(), insitu::LocalBlock::whole(test_grid()));
    const auto f = resume_field(0);
    s.snapshot(0, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }  // destroyed without finalize: interrupted
  auto refusal = [&](insitu::SessionConfig c, const render::GridGeometry& g) -> std::string {
    try {
      insitu::Session s(c, g, insitu::LocalBlock::whole(g));
      return "";
    } catch (const Error& e) {
      return e.what();
    }
  };
  insitu::SessionConfig rig = config(dir, insitu::OutputMode::resume);
  rig.rig = "fibonacci:5";
  EXPECT_NE(refusal(rig, test_grid()).find("the rig ([rig]) differs"), std::string::npos) << refusal(rig, test_grid());
  insitu::SessionConfig task = config(dir, insitu::OutputMode::resume);
  task.tasks[1].isovalues = {0.2, 0.6};
  EXPECT_NE(refusal(task, test_grid()).find("task 2 (\"iso 0.5\""), std::string::npos) << refusal(task, test_grid());
  render::GridGeometry other = test_grid();
  other.dims[0] = 22;
  EXPECT_NE(refusal(config(dir, insitu::OutputMode::resume), other).find("the grid"), std::string::npos);
  insitu::SessionConfig image = config(dir, insitu::OutputMode::resume);
  image.width = 34;
  EXPECT_NE(refusal(image, test_grid()).find("image size"), std::string::npos) << refusal(image, test_grid());
  // The refusals left the database as it was; the same configuration resumes it.
  {
    insitu::Session s(config(dir, insitu::OutputMode::resume), test_grid(), insitu::LocalBlock::whole(test_grid()));
    EXPECT_EQ(s.snapshots(), 1);
    EXPECT_FALSE(s.due(0, 0.0));  // already in the database
    EXPECT_TRUE(s.due(1, 0.2));
    s.finalize();
  }
  EXPECT_EQ(store::Database::open(dir).frame_count(), 1);
  fs::remove_all(dir);
}

TEST(InsituResume, NothingToResumeStartsANewDatabase) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_resume_new_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  {
    insitu::Session s(config(dir, insitu::OutputMode::resume), test_grid(), insitu::LocalBlock::whole(test_grid()));
    EXPECT_EQ(s.snapshots(), 0);
    const auto f = resume_field(0);
    EXPECT_TRUE(s.process(0, 0, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}}));
    s.finalize();
  }
  EXPECT_EQ(store::Database::open(dir).frame_count(), 1);
  fs::remove_all(dir);
}

std::string refusal_of(insitu::Session& s, double time, int step = -1) {
  const auto f = resume_field(0);
  const std::vector<insitu::FieldInput> in{{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}};
  try {
    if (step >= 0)
      s.process(step, time, in);
    else
      s.snapshot(time, in);
  } catch (const Error& e) {  // insitu::UsageError
    return e.what();
  }
  return "";
}

// Issue 42, point 5: NaN or ±inf times were stored (as null in the manifest, which no reader then
// opened) and times going back were stored as given. They are refused at the call, naming the value
// and the previous time, and the database stays readable with the snapshots taken before.
TEST(InsituTimes, NonFiniteAndDecreasingTimesAreRefused) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_times_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  {
    insitu::Session s(config(dir, insitu::OutputMode::create), test_grid(), insitu::LocalBlock::whole(test_grid()));
    const auto f = resume_field(0);
    const std::vector<insitu::FieldInput> in{{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}};
    for (double t : {0.0, 1.0, 2.0}) s.snapshot(t, in);
    EXPECT_NE(refusal_of(s, NAN).find("snapshot: time nan; expected a finite"), std::string::npos) << refusal_of(s, NAN);
    EXPECT_NE(refusal_of(s, INFINITY, 3).find("time inf; expected a finite"), std::string::npos) << refusal_of(s, INFINITY, 3);
    EXPECT_NE(refusal_of(s, -INFINITY).find("time -inf"), std::string::npos);
    EXPECT_THROW((void)s.due(4, NAN), Error);
    const std::string back = refusal_of(s, 1.5);
    EXPECT_NE(back.find("time 1.5 is not after the previous snapshot's time 2"), std::string::npos) << back;
    EXPECT_NE(refusal_of(s, 2.0, 5).find("time 2 is not after"), std::string::npos);  // equal: not after
    EXPECT_EQ(s.snapshots(), 3);
    s.snapshot(4.0, in);
  }  // destroyed without finalize: interrupted, and readable
  const auto db = store::Database::open(dir);
  ASSERT_EQ(db.frame_count(), 4);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(db.manifest().frame_time(k), std::vector<double>({0, 1, 2, 4})[std::size_t(k)]);
  fs::remove_all(dir);
}

// A resumed run repeats the steps since its checkpoint: times at or before the database's last one
// are skipped until it writes its first new snapshot; after that, a time going back is refused.
TEST(InsituTimes, ResumeSkipsRepeatedTimesOnlyBeforeItsFirstNewSnapshot) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_times_resume_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const auto f = resume_field(0);
  const std::vector<insitu::FieldInput> in{{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}};
  {
    insitu::Session s(config(dir, insitu::OutputMode::create), test_grid(), insitu::LocalBlock::whole(test_grid()));
    for (int step = 0; step < 3; ++step) s.process(step, time_of(step), in);
  }  // interrupted after t = 0, 0.2, 0.4
  {
    insitu::Session s(config(dir, insitu::OutputMode::resume), test_grid(), insitu::LocalBlock::whole(test_grid()));
    EXPECT_FALSE(s.process(1, time_of(1), in));  // repeated: skipped, no error
    EXPECT_FALSE(s.process(2, time_of(2), in));
    EXPECT_TRUE(s.process(3, time_of(3), in));
    const std::string back = refusal_of(s, 0.5, 4);
    EXPECT_NE(back.find("time 0.5 is not after the previous snapshot's time 0.6"), std::string::npos) << back;
    EXPECT_NE(back.find("a resumed run skips only"), std::string::npos) << back;
    EXPECT_TRUE(s.process(4, time_of(4), in));
    s.finalize();
  }
  EXPECT_EQ(store::Database::open(dir).frame_count(), 5);
  fs::remove_all(dir);
}

std::string resume_refusal(const insitu::SessionConfig& c) {
  try {
    insitu::Session s(c, test_grid(), insitu::LocalBlock::whole(test_grid()));
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

// Issue 42, point 4: mode = "resume" on a FINISHED database took it (one info line, exit 0) and
// skipped every snapshot of the rerun, whose times were all in the database: a rerun with a changed
// source kept the old movies. A complete database is refused, naming the directory and the options.
TEST(InsituResume, RefusesACompleteDatabase) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_resume_complete_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  run(dir, insitu::OutputMode::create, 0);  // finished: complete, kSteps snapshots
  const std::string why = resume_refusal(config(dir, insitu::OutputMode::resume));
  EXPECT_NE(why.find(dir.string() + ": holds a complete database (its run finished: 6 snapshots up to time 1)"),
            std::string::npos) << why;
  EXPECT_NE(why.find("mode = \"overwrite\""), std::string::npos) << why;
  EXPECT_NE(why.find("another [output] dir"), std::string::npos) << why;
  EXPECT_NE(why.find("resume_complete = true"), std::string::npos) << why;
  const auto db = store::Database::open(dir);  // untouched
  EXPECT_EQ(db.status(), store::Status::complete);
  EXPECT_EQ(db.frame_count(), kSteps);
  fs::remove_all(dir);
}

// ... unless the configuration asks for it: [output] resume_complete = true appends to the finished run.
TEST(InsituResume, ResumeCompleteAppendsToAFinishedRun) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_resume_append_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  run(dir, insitu::OutputMode::create, 0);
  EXPECT_TRUE(insitu::parse_session_config_text(std::string(kConfig) + "[output]\nresume_complete = true\n", "t").resume_complete);
  insitu::SessionConfig c = config(dir, insitu::OutputMode::resume);
  c.resume_complete = true;
  {
    insitu::Session s(c, test_grid(), insitu::LocalBlock::whole(test_grid()));
    EXPECT_EQ(s.snapshots(), kSteps);
    const auto f = resume_field(time_of(kSteps));
    EXPECT_TRUE(s.process(kSteps, time_of(kSteps), {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}}));
    s.finalize();
  }
  EXPECT_EQ(store::Database::open(dir).frame_count(), kSteps + 1);
  fs::remove_all(dir);
}

// Issue 42, point 4: a changed every_steps (or every_time) on resume was accepted silently; it is
// named like every other change, and the database is left as it was.
TEST(InsituResume, RefusesAnotherSchedule) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_resume_schedule_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  {
    insitu::Session s(config(dir, insitu::OutputMode::create), test_grid(), insitu::LocalBlock::whole(test_grid()));
    const auto f = resume_field(0);
    s.snapshot(0, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }  // interrupted
  insitu::SessionConfig steps = config(dir, insitu::OutputMode::resume);
  steps.schedule.every_steps = 2;
  const std::string a = resume_refusal(steps);
  EXPECT_NE(a.find("the schedule ([schedule]) differs (every_steps = 1 in the database, every_steps = 2 in this run)"),
            std::string::npos) << a;
  insitu::SessionConfig time = config(dir, insitu::OutputMode::resume);
  time.schedule.every_steps = 0;
  time.schedule.every_time = 0.25;
  const std::string b = resume_refusal(time);
  EXPECT_NE(b.find("every_steps = 1 in the database, every_time = 0.25 in this run"), std::string::npos) << b;
  insitu::Session s(config(dir, insitu::OutputMode::resume), test_grid(), insitu::LocalBlock::whole(test_grid()));
  EXPECT_EQ(s.snapshots(), 1);
  s.finalize();
  fs::remove_all(dir);
}

}  // namespace

// mode = "overwrite" over an interrupted run keeps it beside (issue 42, point 8: a restart from step 50
// with "overwrite" deleted part 1 without a word); a complete database is replaced as before, and
// keep_interrupted = false (the commands' --overwrite) deletes an interrupted one.
TEST(InsituResume, OverwriteKeepsAnInterruptedRunBeside) {
  const fs::path base = fs::temp_directory_path() / ("insitu_keep_" + std::to_string(::getpid()));
  fs::remove_all(base);
  fs::create_directories(base);
  const fs::path dir = base / "db", kept = base / "db.interrupted-1";
  {
    insitu::Session s(config(dir, insitu::OutputMode::create), test_grid(), insitu::LocalBlock::whole(test_grid()));
    for (int step = 0; step < 2; ++step) {
      const auto f = resume_field(time_of(step));
      s.process(step, time_of(step), {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
    }
  }  // no finalize: interrupted
  ASSERT_EQ(store::Database::open(dir).status(), store::Status::interrupted);
  run(dir, insitu::OutputMode::overwrite, 3);  // the restart that should have resumed
  ASSERT_TRUE(fs::exists(kept / "panoptes.json"));
  EXPECT_EQ(store::Database::open(kept).frame_count(), 2);
  EXPECT_EQ(store::Database::open(kept).status(), store::Status::interrupted);
  EXPECT_EQ(store::Database::open(dir).frame_count(), kSteps - 3);
  // Complete: replaced, nothing kept.
  run(dir, insitu::OutputMode::overwrite, 4);
  EXPECT_FALSE(fs::exists(base / "db.interrupted-2"));
  EXPECT_EQ(store::Database::open(dir).frame_count(), kSteps - 4);
  // keep_interrupted = false: deleted.
  {
    insitu::SessionConfig c = config(dir, insitu::OutputMode::overwrite);
    insitu::Session s(c, test_grid(), insitu::LocalBlock::whole(test_grid()));
    const auto f = resume_field(0);
    s.process(0, 0, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }
  insitu::SessionConfig c = config(dir, insitu::OutputMode::overwrite);
  c.keep_interrupted = false;
  { insitu::Session s(c, test_grid(), insitu::LocalBlock::whole(test_grid())); }
  EXPECT_FALSE(fs::exists(base / "db.interrupted-2"));
  fs::remove_all(base);
}
