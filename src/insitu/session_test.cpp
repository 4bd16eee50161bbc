#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/memory.hpp"
#include "grid/grid_description.hpp"
#include "insitu/grid_adapter.hpp"
#include "insitu/resources.hpp"
#include "insitu/session.hpp"
#include "render/synthetic_fields.hpp"
#include "store/database.hpp"

using namespace panoptes;
namespace fs = std::filesystem;

namespace {

std::string error_of(const std::string& toml) {
  try {
    (void)insitu::parse_session_config_text(toml, "test.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

const char* kTask = "[[task]]\nname = \"v\"\nfield = \"f\"\n";

TEST(InsituConfig, DefaultsAndSweeps) {
  const auto c = insitu::parse_session_config_text(
      std::string(kTask) + "[[task]]\nname = \"iso\"\ntype = \"isosurface\"\nfield = \"f\"\nisovalues = [0.1, 0.2, 0.3]\n",
      "t");
  EXPECT_EQ(c.width, 920);
  EXPECT_EQ(c.height, 896);
  EXPECT_EQ(c.rig, "yinyang");
  EXPECT_EQ(c.schedule.every_steps, 10);
  ASSERT_EQ(c.tasks.size(), 2u);
  EXPECT_EQ(c.tasks[1].isovalues.size(), 3u);
  EXPECT_TRUE(c.tasks[0].windows[0].relative);
  EXPECT_TRUE(c.time_units.empty());
  EXPECT_TRUE(c.field_units.empty());
  const auto u = insitu::parse_session_config_text(
      std::string("[output]\ntime_units = \"s\"\nfield_units = { f = \"1/s\" }\n") + kTask, "u");
  EXPECT_EQ(u.time_units, "s");
  EXPECT_EQ(u.field_units.at("f"), "1/s");
  EXPECT_THROW(insitu::parse_session_config_text(std::string("[output]\nfield_units = { f = 1 }\n") + kTask, "u"), Error);
}

TEST(InsituConfig, ErrorsNameTheKey) {
  EXPECT_NE(error_of(std::string(kTask) + "[image]\nwidht = 3\n").find("image.widht: unknown key"), std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[image]\nwidth = \"big\"\n").find("image.width: expected an integer"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[image]\nwidth = 1\n").find("expected 2..16384"), std::string::npos);
  EXPECT_NE(error_of("").find("no [[task]] given"), std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[schedule]\nevery_steps = 5\nevery_time = 0.1\n").find("exactly one of"),
            std::string::npos);
  EXPECT_NE(error_of("[[task]]\nname = \"v\"\nfield = \"f\"\npreset = \"purple\"\n").find("unknown preset \"purple\""),
            std::string::npos);
  EXPECT_NE(error_of("[[task]]\nname = \"v\"\ntype = \"volume2\"\nfield = \"f\"\n").find("exactly two fields"),
            std::string::npos);
  EXPECT_NE(error_of("[[task]]\nname = \"v\"\ntype = \"cloud\"\nfield = \"f\"\n").find("task[0].type: \"cloud\""),
            std::string::npos);
  EXPECT_NE(error_of("[[task]]\nname = \"s\"\ntype = \"slice\"\nfield = \"f\"\naxis = \"w\"\n").find("task[0].axis"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + kTask).find("used twice"), std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[rig]\nspec = \"cube:3\"\n").find("rig.spec"), std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[video]\ncrf = 99\n").find("video"), std::string::npos);
  EXPECT_NE(error_of("[[task]]\nname = \"v\"\nfield = \"f\"\nwindow = [1, 0]\n").find("lo < hi"), std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[seismic]\nx = 1\n").find("seismic: unknown key"), std::string::npos);
  EXPECT_NE(error_of("x = [").find("TOML syntax error"), std::string::npos);
}

// Issue 15: absurd configurations are refused before anything is built.
TEST(InsituConfig, IntegersAreRangeCheckedBeforeNarrowing) {
  EXPECT_NE(error_of(std::string(kTask) + "[image]\nwidth = 4294967336\n")
                .find("image.width: 4294967336 is out of range"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[schedule]\nmax_snapshots = 4294967297\n").find("schedule.max_snapshots"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[video]\ngop = -4294967295\n").find("video.gop"), std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[resources]\ncheck_memory = 1\n").find("resources.check_memory"),
            std::string::npos);
  EXPECT_FALSE(insitu::parse_session_config_text(std::string(kTask) + "[resources]\ncheck_memory = false\n", "t")
                   .check_memory);
}

// Issue 45: 360° frames have their own adaptive tolerance (10/255 by default), in 1/255 in the file.
TEST(InsituConfig, EquirectToleranceIsItsOwnKey) {
  EXPECT_FLOAT_EQ(insitu::parse_session_config_text(std::string(kTask), "t").render.equirect_tolerance, 11.0f / 255);
  const auto c = insitu::parse_session_config_text(std::string(kTask) + "[render]\nequirect_tolerance = 4\n", "t");
  EXPECT_FLOAT_EQ(c.render.equirect_tolerance, 4.0f / 255);
  EXPECT_FLOAT_EQ(c.render.adaptive_tolerance, 4.0f / 255);
  EXPECT_NE(error_of(std::string(kTask) + "[render]\nequirect_tolerance = 300\n").find("render.equirect_tolerance"),
            std::string::npos);
}

// Issue 45: sessions sample adaptively unless told otherwise (with or without a [render] table), as
// panoptes render does; anti-aliased isosurfaces likewise.
TEST(InsituConfig, AdaptiveSamplingIsTheDefault) {
  const auto bare = insitu::parse_session_config_text(std::string(kTask), "t");
  EXPECT_TRUE(bare.render.adaptive);
  EXPECT_TRUE(bare.render.iso_antialias);
  EXPECT_TRUE(insitu::parse_session_config_text(std::string(kTask) + "[render]\nsample_distance = 1.0\n", "t").render.adaptive);
  EXPECT_FALSE(insitu::parse_session_config_text(std::string(kTask) + "[render]\nadaptive = false\n", "t").render.adaptive);
}

// The adaptive lattice's spacing: 4 pixels by default, a power of two up to 32 (cells split at midpoints).
TEST(InsituConfig, AdaptiveStrideIsAPowerOfTwo) {
  EXPECT_EQ(insitu::parse_session_config_text(std::string(kTask), "t").render.adaptive_stride, 4);
  EXPECT_EQ(insitu::parse_session_config_text(std::string(kTask) + "[render]\nadaptive_stride = 8\n", "t").render.adaptive_stride, 8);
  for (const char* bad : {"6", "1", "64", "0", "-4", "4.5"})
    EXPECT_NE(error_of(std::string(kTask) + "[render]\nadaptive_stride = " + bad + "\n").find("render.adaptive_stride"),
              std::string::npos)
        << bad;
}

TEST(InsituConfig, RigSpecsAreBounded) {
  // More cameras over all shells than the limit (each shell alone is allowed).
  EXPECT_NE(error_of(std::string(kTask) + "[rig]\nspec = \"fibonacci:5000000@2,3,4\"\n").find("is more than the limit"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kTask) + "[rig]\nspec = \"fibonacci:10000001\"\n").find("is more than the limit"),
            std::string::npos);
}

// A rig file must be a regular file: /dev/zero used to be read for ever.
TEST(InsituResources, RigFileMustBeARegularFile) {
  auto c = insitu::parse_session_config_text(std::string(kTask) + "[rig]\nspec = \"file:/dev/zero\"\n", "t");
  const render::GridGeometry grid{{16, 16, 16}, {0, 0, 0}, {1, 1, 1}};
  try {
    (void)insitu::rig_camera_count(c, grid);
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/zero: is a character device; expected a regular camera file"),
              std::string::npos)
        << e.what();
  }
}

TEST(InsituResources, RanksSplitByCamerasWhenTheWholeGridIsSmall) {
  auto c = insitu::parse_session_config_text(std::string(kTask), "t");  // one volume field: 21 B per point
  EXPECT_EQ(c.parallel, insitu::RenderSplit::automatic);
  const render::GridGeometry small{{128, 128, 64}, {0, 0, 0}, {1, 1, 1}};    // 22 MB
  const render::GridGeometry big{{512, 512, 512}, {0, 0, 0}, {1, 1, 1}};     // 2.8 GB
  EXPECT_EQ(insitu::choose_render_split(c, small, 26, 2), insitu::RenderSplit::cameras);
  EXPECT_EQ(insitu::choose_render_split(c, big, 26, 2), insitu::RenderSplit::bricks);
  EXPECT_EQ(insitu::choose_render_split(c, small, 3, 4), insitu::RenderSplit::bricks);  // ranks would idle
  EXPECT_EQ(insitu::choose_render_split(c, small, 26, 1), insitu::RenderSplit::bricks);  // one rank: the whole grid
  c = insitu::parse_session_config_text(std::string(kTask) + "[resources]\nparallel = \"cameras\"\n", "t");
  EXPECT_EQ(insitu::choose_render_split(c, big, 26, 2), insitu::RenderSplit::cameras);   // asked for
  c = insitu::parse_session_config_text(std::string(kTask) + "[resources]\nparallel = \"bricks\"\n", "t");
  EXPECT_EQ(insitu::choose_render_split(c, small, 26, 2), insitu::RenderSplit::bricks);
  EXPECT_NE(error_of(std::string(kTask) + "[resources]\nparallel = \"rays\"\n")
                .find("resources.parallel: \"rays\"; expected \"auto\", \"cameras\" or \"bricks\""),
            std::string::npos);
}

TEST(InsituResources, HugeImagesAndRigsDoNotFitAndSmallOnesDo) {
  auto c = insitu::parse_session_config_text(std::string(kTask), "t");
  const double points = 64.0 * 64 * 64;
  const MemoryLimit machine{24e9, "test"};
  EXPECT_EQ(memory_refusal(insitu::estimate_session_memory(c, points, 130, 1, 2), machine, 1, "x", "y"), "");
  c.width = c.height = 16384;  // 268 Mpixel per camera: several GB of partial images and writers
  const std::string why = memory_refusal(insitu::estimate_session_memory(c, points, 130, 1, 2), machine, 1, "this session", "--force");
  EXPECT_NE(why.find("this session needs about"), std::string::npos) << why;
  EXPECT_NE(why.find("24.0 GB available (test)"), std::string::npos) << why;
  c.width = 920, c.height = 896;
  // 10^7 cameras: 10^7 open writers alone are ~11 TB.
  EXPECT_NE(memory_refusal(insitu::estimate_session_memory(c, points, 10'000'000, 1, 2), machine, 1, "x", "y"), "");
  EXPECT_THROW(insitu::check_open_streams(10'000'000, 3, 1), Error);
  EXPECT_THROW(insitu::check_open_streams(2'000'000'000, 2, 1), Error);  // cameras x tasks beyond an int
  EXPECT_EQ(insitu::check_open_streams(130, 3, 4), 98);
}

TEST(InsituResources, SessionRefusesBeforeBuildingAnything) {
  const fs::path dir = fs::temp_directory_path() / ("panoptes_resources_" + std::to_string(::getpid()));
  // 16 tasks of 16384^2 pixels: ~0.4 TB of partial images alone, more than any machine this runs on.
  std::string windows = "windows = [";
  for (int i = 1; i <= 16; ++i) windows += "[0, " + std::to_string(i) + "],";
  windows.back() = ']';
  auto c = insitu::parse_session_config_text(
      std::string(kTask) + windows + "\n[image]\nwidth = 16384\nheight = 16384\n", "t");
  c.output_dir = dir.string();
  const render::GridGeometry grid{{16, 16, 16}, {0, 0, 0}, {1, 1, 1}};
  try {
    insitu::Session s(c, grid, insitu::LocalBlock::whole(grid));
    FAIL() << "a 16384x16384 image for 130 cameras was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("needs about"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("check_memory = false"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));  // nothing was written
}

insitu::SessionConfig small_config(const std::string& dir) {
  auto c = insitu::parse_session_config_text(R"(
[image]
width = 32
height = 32
[rig]
spec = "fibonacci:4"
[schedule]
every_steps = 1
[[task]]
name = "v"
field = "f"
[[task]]
name = "iso"
type = "isosurface"
field = "f"
isovalues = [0.2, 0.5]
relative = true
)",
                                              "small");
  c.output_dir = dir;
  c.mode = insitu::OutputMode::overwrite;
  return c;
}

render::GridGeometry grid() { return {{20, 18, 16}, {0, 0, 0}, {1, 1, 1}}; }

std::vector<float> field(double t) {
  const render::GridGeometry g = grid();
  const std::vector<render::WaveFront> fronts{{g.centre(), 3 + 2 * t, 1.5, 1.0}};
  return render::wave_field(g, fronts);
}

TEST(InsituSession, ExpandsSweepsIntoTasks) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_single_" + std::to_string(::getpid()));
  {
    insitu::Session s(small_config(dir), grid(), insitu::LocalBlock::whole(grid()));
    EXPECT_EQ(s.camera_count(), 4);
    EXPECT_EQ(s.task_count(), 3);
    EXPECT_EQ(s.field_names(), std::vector<std::string>{"f"});
    s.finalize();
  }
  fs::remove_all(dir);
}

// Issue 45: one rank rendering one sweep takes render_sweep() (sweep_rendering()), and its frames are
// those of the general path, which the same sweep beside a second task takes.
TEST(InsituSession, ASweepRendersAsTheGeneralPathDoes) {
  const std::string sweep_task = R"(
[image]
width = 48
height = 40
[rig]
spec = "fibonacci:3"
[render]
iso_antialias = false
[[task]]
name = "iso"
type = "isosurface"
field = "f"
isovalues = [0.6, -0.2, 0.1, 0.35]
relative = true
)";
  const std::string other_task = "[[task]]\nname = \"v\"\nfield = \"f\"\n";
  const auto f = field(0.5);
  auto run = [&](const std::string& text, const fs::path& dir, bool expect_sweep) {
    auto cfg = insitu::parse_session_config_text(text, "sweep");
    cfg.output_dir = dir.string();
    cfg.mode = insitu::OutputMode::overwrite;
    EXPECT_EQ(insitu::sweep_rendering(cfg, 1), expect_sweep);
    std::vector<Image> frames(12);  // [camera][isovalue]
    {
      insitu::Session s(cfg, grid(), insitu::LocalBlock::whole(grid()));
      s.set_frame_observer([&](int camera, int task, int, const Image& image) {
        if (task < 4) frames[std::size_t(camera * 4 + task)] = image;
      });
      s.snapshot(0, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
      s.finalize();
      EXPECT_EQ(s.stats().frames_encoded, 3 * std::int64_t(cfg.tasks.size() == 1 ? 4 : 5));
    }
    fs::remove_all(dir);
    return frames;
  };
  const fs::path base = fs::temp_directory_path() / ("insitu_sweep_" + std::to_string(::getpid()));
  const std::vector<Image> swept = run(sweep_task, base.string() + "a", true);
  const std::vector<Image> general = run(sweep_task + other_task, base.string() + "b", false);
  for (std::size_t i = 0; i < swept.size(); ++i) {
    ASSERT_EQ(swept[i].pixels.size(), general[i].pixels.size()) << "camera " << i / 4 << ", isovalue " << i % 4;
    EXPECT_GE(std::min(99.0, psnr(swept[i], general[i])), 45.0) << "camera " << i / 4 << ", isovalue " << i % 4;
  }
}

TEST(InsituSession, MissingFieldIsAnError) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_missing_" + std::to_string(::getpid()));
  insitu::Session s(small_config(dir), grid(), insitu::LocalBlock::whole(grid()));
  EXPECT_THROW(s.snapshot(0, {{"g", nullptr, insitu::ScalarType::f32, {0, 0, 0}}}), Error);
  s.finalize();
  fs::remove_all(dir);
}

// Issue 42, point 6: a FieldInput stride of 2^62 floats wrapped (2^64 bytes) and read plane 0 for every
// z; strides whose reach overflows 64-bit offsets are refused at the snapshot, naming the field.
TEST(InsituSession, StridesThatOverflowAreRefused) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_strides_" + std::to_string(::getpid()));
  insitu::Session s(small_config(dir), grid(), insitu::LocalBlock::whole(grid()));
  const auto f = field(0);
  const std::int64_t nx = grid().dims[0], ny = grid().dims[1];
  try {
    s.snapshot(0, {{"f", f.data(), insitu::ScalarType::f32, {1, nx, std::int64_t(1) << 62}}});
    ADD_FAILURE() << "a stride of 2^62 was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("field \"f\": strides (1, " + std::to_string(nx) + ", 4611686018427387904)"),
              std::string::npos) << e.what();
  }
  EXPECT_EQ(s.snapshots(), 0);
  s.snapshot(0, {{"f", f.data(), insitu::ScalarType::f32, {1, nx, nx * ny}}});
  s.finalize();
  fs::remove_all(dir);
}

TEST(InsituSession, SnapshotsScheduleAndFinalize) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_sched_" + std::to_string(::getpid()));
  auto cfg = small_config(dir);
  cfg.schedule.every_steps = 0;
  cfg.schedule.every_time = 0.25;
  cfg.time_units = "s";
  cfg.field_units = {{"f", "1/s"}};
  insitu::Session s(cfg, grid(), insitu::LocalBlock::whole(grid()));
  int taken = 0;
  for (int step = 0; step < 10; ++step) {
    const double t = 0.1 * step;
    const auto f = field(t);
    taken += s.process(step, t, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }
  EXPECT_EQ(taken, 4);  // t = 0, 0.3 (≥ 0.25), 0.5, 0.8 (≥ 0.75)
  s.finalize();
  const auto db = store::Database::open(dir);
  EXPECT_EQ(db.status(), store::Status::complete);
  EXPECT_EQ(db.frame_count(), 4);
  ASSERT_EQ(db.manifest().axes.size(), 1u);
  EXPECT_EQ(db.manifest().axes[0].name, "iso isovalue");
  EXPECT_EQ(db.manifest().step_task_on_axis(1, "iso isovalue", 1), 2);
  EXPECT_NEAR(db.manifest().frame_time(1), 0.3, 1e-12);
  // Issue 34: what the colour legends need — units, each frame's reference of the relative windows
  // (the 99.9th percentile of |f|, grows as the front does) and the transfer function as data.
  const store::Manifest& m = db.manifest();
  EXPECT_EQ(m.time_units, "s");
  ASSERT_EQ(m.fields.size(), 1u);
  EXPECT_EQ(m.fields[0].name, "f");
  EXPECT_EQ(m.fields[0].units, "1/s");
  ASSERT_EQ(m.fields[0].references.size(), 4u);
  for (double r : m.fields[0].references) EXPECT_GT(r, 0.5);
  const auto& tf = m.tasks[0].parameters.at("transfer_function");
  EXPECT_EQ(tf.at("colour").size(), 4u);  // the "hot" preset's control points
  EXPECT_EQ(m.tasks[1].parameters.at("colour").size(), 3u);
  fs::remove_all(dir);
}

// Runs a session that SIGKILLs itself in the middle of its third snapshot (camera 2 of frame 2).
void run_until_killed(const fs::path& dir, const std::string& layout = "auto") {
  auto cfg = small_config(dir);
  cfg.layout = layout;
  insitu::Session s(cfg, grid(), insitu::LocalBlock::whole(grid()));
  s.set_frame_observer([](int camera, int, int frame, const Image&) {
    if (frame == 2 && camera == 2) ::raise(SIGKILL);
  });
  for (int step = 0; step < 5; ++step) {
    const auto f = field(0.2 * step);
    s.process(step, 0.2 * step, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }
  s.finalize();
}

// A run SIGKILLed in the middle of its third snapshot leaves a database that opens as interrupted
// with the two completed snapshots playable in every stream.
TEST(InsituSession, KilledRunOpensInterrupted) {
  // The run happens in a re-executed copy of this binary ("threadsafe" death test), not a plain
  // fork: a child forked after earlier tests started OpenMP's thread pool deadlocks in its first
  // parallel region (libgomp is not fork-safe), which hung this test when the binary ran whole.
  // The child re-runs this body, so it finds the directory through the environment.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  if (!std::getenv("PANOPTES_TEST_KILLED_DIR")) {
    const fs::path d = fs::temp_directory_path() / ("insitu_killed_" + std::to_string(::getpid()));
    ::setenv("PANOPTES_TEST_KILLED_DIR", d.c_str(), 1);
  }
  const fs::path dir = std::getenv("PANOPTES_TEST_KILLED_DIR");
  fs::remove_all(dir);
  EXPECT_EXIT(run_until_killed(dir), ::testing::KilledBySignal(SIGKILL), "");
  const auto db = store::Database::open(dir);
  EXPECT_EQ(db.status(), store::Status::interrupted);
  EXPECT_EQ(db.frame_count(), 2);
  for (int c = 0; c < db.camera_count(); ++c)
    for (int t = 0; t < db.task_count(); ++t) {
      auto r = db.stream(c, t);
      ASSERT_GE(r->frame_count(), 2) << "camera " << c << " task " << t;
      const Image img = r->read_rgba(1);
      EXPECT_EQ(img.width, 32);
    }
  fs::remove_all(dir);
}

// Issue 46: the same with [output] layout = "packed": one pack and one index, no movie file; a kill
// in the third snapshot keeps two; resume continues into a new segment and every frame plays.
TEST(InsituSession, PackedLayoutSurvivesAKillAndResumes) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  if (!std::getenv("PANOPTES_TEST_PACKED_DIR")) {
    const fs::path d = fs::temp_directory_path() / ("insitu_packed_" + std::to_string(::getpid()));
    ::setenv("PANOPTES_TEST_PACKED_DIR", d.c_str(), 1);
  }
  const fs::path dir = std::getenv("PANOPTES_TEST_PACKED_DIR");
  fs::remove_all(dir);
  EXPECT_EXIT(run_until_killed(dir, "packed"), ::testing::KilledBySignal(SIGKILL), "");
  {
    const auto db = store::Database::open(dir);
    ASSERT_TRUE(db.packed());
    EXPECT_EQ(db.frame_count(), 2);
    EXPECT_FALSE(fs::exists(dir / "movies"));
    EXPECT_TRUE(db.validate_streams(1, true).problems.empty());
  }
  auto cfg = small_config(dir.string());
  cfg.mode = insitu::OutputMode::resume;
  {
    insitu::Session s(cfg, grid(), insitu::LocalBlock::whole(grid()));
    for (int step = 0; step < 5; ++step) {
      const auto f = field(0.2 * step);
      s.process(step, 0.2 * step, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
    }
    s.finalize();
  }
  const auto db = store::Database::open(dir);
  EXPECT_EQ(db.status(), store::Status::complete);
  EXPECT_EQ(db.frame_count(), 5);
  EXPECT_EQ(db.manifest().packs.size(), 2u);
  const store::StreamReport report = db.validate_streams(1, true);
  EXPECT_TRUE(report.problems.empty()) << report.problems.front().message;
  std::size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 6u);  // manifest, camera table, 2 segments x (pack + index)
  fs::remove_all(dir);
}

// A stop request (SIGINT/SIGTERM with the handlers installed) stops the session before its next
// snapshot; the database is stored as interrupted with the snapshots taken, and its lock is gone.
TEST(InsituSession, StopRequestLeavesTheDatabaseInterrupted) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_stop_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  {
    insitu::Session s(small_config(dir), grid(), insitu::LocalBlock::whole(grid()));
    const auto f = field(0.0);
    s.snapshot(0.0, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
    request_stop(SIGTERM);
    try {
      s.snapshot(0.2, {{"f", f.data(), insitu::ScalarType::f32, {0, 0, 0}}});
      ADD_FAILURE() << "no Interrupted";
    } catch (const Interrupted& e) {
      EXPECT_EQ(e.signal(), SIGTERM);
      EXPECT_NE(std::string(e.what()).find("SIGTERM"), std::string::npos) << e.what();
    }
    clear_stop_request();
  }
  const auto db = store::Database::open(dir);
  EXPECT_EQ(db.stored_status(), store::Status::interrupted);
  EXPECT_EQ(db.frame_count(), 1);
  EXPECT_FALSE(fs::exists(dir / store::kLockFileName));
  fs::remove_all(dir);
}

TEST(InsituSession, BadBlocksAreRejected) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_badblock_" + std::to_string(::getpid()));
  insitu::LocalBlock b = insitu::LocalBlock::whole(grid());
  b.extent[2] -= 1;  // one plane owned by nobody
  try {
    insitu::Session s(small_config(dir), grid(), b);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("do not partition"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// Valid ghost layers are at most the stored ones (or -1 = all): anything else is refused naming the
// rank, the member, the axis and what was expected.
TEST(InsituSession, ValidGhostLayersAreChecked) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_badvalid_" + std::to_string(::getpid()));
  auto refusal = [&](const insitu::LocalBlock& b) -> std::string {
    try {
      insitu::Session s(small_config(dir), grid(), b);
      return "";
    } catch (const Error& e) {
      return e.what();
    }
  };
  insitu::LocalBlock b = insitu::LocalBlock::whole(grid());
  b.valid_hi[2] = 1;  // one layer valid of none stored
  const std::string m = refusal(b);
  EXPECT_NE(m.find("rank 0: valid_hi = 1 on axis z: expected -1 (every stored layer) or 0..0"), std::string::npos) << m;
  b.valid_hi[2] = -2;
  EXPECT_NE(refusal(b).find("valid_hi = -2"), std::string::npos) << refusal(b);
  b.valid_hi[2] = 0;  // 0 valid layers (and edges_valid) are fine
  b.edges_valid = true;
  EXPECT_EQ(refusal(b), "");
  fs::remove_all(dir);
}

}  // namespace

// The grid stage is in the memory estimate (issue 44, point 3): an 8x200x400 spherical shell resampled
// onto its default 400^3 cover needs ~2.5 GB (resampling plan, corner copies, field copies); under a
// 400 MB limit the session refuses before the grid stage is built, naming it, instead of being admitted.
TEST(SessionResources, TheGridStageIsInTheMemoryEstimate) {
  std::vector<double> r(8), theta(200), phi(400);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = 0.5 + 0.5 * double(i) / 7;
  for (std::size_t i = 0; i < theta.size(); ++i) theta[i] = 0.01 + (3.14159265 - 0.02) * double(i) / 199;
  for (std::size_t i = 0; i < phi.size(); ++i) phi[i] = -3.14159265 + 2 * 3.14159265 * double(i) / 400;
  const grid::GridDescription shell = grid::GridDescription::spherical(r, theta, phi);
  insitu::SessionConfig cfg = insitu::parse_session_config_text(
      "[image]\nwidth = 32\nheight = 32\n[rig]\nspec = \"fibonacci:2\"\n[[task]]\nname = \"v\"\nfield = \"f\"\n", "t");
  cfg.output_dir = (fs::temp_directory_path() / ("grid_memory_" + std::to_string(::getpid()))).string();
  const char* old = std::getenv("PANOPTES_MEMORY_LIMIT");
  const std::string saved = old ? old : "";
  ::setenv("PANOPTES_MEMORY_LIMIT", "400M", 1);
  std::string message;
  try {
    insitu::Session s(cfg, shell, {insitu::GridBlock::whole(shell)}, insitu::ResampleOptions{});
  } catch (const Error& e) {
    message = e.what();
  }
  if (old) ::setenv("PANOPTES_MEMORY_LIMIT", saved.c_str(), 1);
  else ::unsetenv("PANOPTES_MEMORY_LIMIT");
  EXPECT_NE(message.find("grid stage: resampling plan"), std::string::npos) << message;
  EXPECT_NE(message.find("with its grid stage"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(cfg.output_dir)) << "refused after the database was created";
  fs::remove_all(cfg.output_dir);
}
