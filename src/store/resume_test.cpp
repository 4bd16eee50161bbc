// DatabaseWriter::resume: a database left interrupted is continued after a restart — the frames and
// times of its last checkpoint stay (frames written after it are dropped), appends go on in the same
// movies, and a manifest that would make it another dataset is refused naming the difference.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.hpp"
#include "core/frame_stamp.hpp"
#include "store/database.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"
#include "video/movie_reader.hpp"

using namespace panoptes;
using namespace panoptes::store;
using panoptes::store::testing::error_of;
using panoptes::store::testing::sample_manifest;
using panoptes::store::testing::TempDir;
namespace fs = std::filesystem;

namespace {

void append_snapshot(DatabaseWriter& w, const Manifest& m, int f) {
  for (int c = 0; c < m.camera_count(); ++c)
    for (int t = 0; t < m.task_count(); ++t) w.append(c, t, synthetic_frame(c, t, f, m.image.width, m.image.height));
  w.set_time(f, 0.5 * f);
  w.checkpoint();
}

// 3 checkpointed snapshots, then a 4th written to one stream only when the writer is abandoned.
void write_interrupted(const fs::path& dir, const Manifest& m) {
  DatabaseWriter w = DatabaseWriter::create(dir, m);
  for (int f = 0; f < 3; ++f) append_snapshot(w, m, f);
  w.append(0, 0, synthetic_frame(0, 0, 3, m.image.width, m.image.height));
  w.flush();  // durable in the movie, but not counted by any checkpoint
}

void expect_continued(const fs::path& dir, const Manifest& m) {
  const Database db = Database::open(dir);
  ASSERT_EQ(db.status(), Status::complete);
  ASSERT_EQ(db.frame_count(), 5);
  ASSERT_EQ(db.manifest().times, (std::vector<double>{0, 0.5, 1, 1.5, 2}));
  for (int c = 0; c < m.camera_count(); ++c)
    for (int t = 0; t < m.task_count(); ++t) {
      auto r = db.stream(c, t);
      ASSERT_EQ(r->frame_count(), 5) << "camera " << c << " task " << t;  // the uncounted frame is gone
      for (int f = 0; f < 5; ++f) {
        const auto stamp = read_frame_stamp(r->read_rgba(f));
        ASSERT_TRUE(stamp.has_value()) << "camera " << c << " task " << t << " frame " << f;
        EXPECT_EQ(*stamp, (FrameStamp{std::uint32_t(c), std::uint32_t(t), std::uint32_t(f)}));
      }
    }
  for (const auto& e : fs::recursive_directory_iterator(dir))
    EXPECT_NE(e.path().extension(), ".resume") << e.path();  // no temporary copy left behind
}

TEST(DatabaseResume, ContinuesTheCheckpointedFramesAndTimes) {
  for (int gop : {1, 3}) {  // intra-only movies, and movies whose copied frames predict from others
    SCOPED_TRACE("gop " + std::to_string(gop));
    TempDir dir;
    Manifest m = sample_manifest(2, 2);
    m.video.gop = gop;
    write_interrupted(dir.path, m);
    ASSERT_EQ(Database::open(dir.path).frame_count(), 3);
    {
      DatabaseWriter w = DatabaseWriter::resume(dir.path, m);
      EXPECT_EQ(w.manifest().frames_written, 3);
      EXPECT_EQ(w.complete_frames(), 3);
      EXPECT_EQ(w.manifest().provenance.extra.at("note"), "a b");
      for (int f = 3; f < 5; ++f) append_snapshot(w, m, f);
      w.finalize();
    }
    expect_continued(dir.path, m);
  }
}

TEST(DatabaseResume, SeveralWritersEachContinueTheirOwnCameras) {
  TempDir dir;
  const Manifest m = sample_manifest(3, 2);
  write_interrupted(dir.path, m);
  // A restart on two "ranks": the root owns camera 0 and writes the manifest, the other cameras 1, 2.
  DatabaseWriter root = DatabaseWriter::resume(dir.path, m, {false, {0}, true, ""});
  const int frames = root.manifest().frames_written;
  DatabaseWriter other = DatabaseWriter::resume(dir.path, m, {false, {1, 2}, false, ""}, frames);
  for (int f = 3; f < 5; ++f) {
    for (int t = 0; t < 2; ++t) {
      root.append(0, t, synthetic_frame(0, t, f, 64, 64));
      for (int c = 1; c < 3; ++c) other.append(c, t, synthetic_frame(c, t, f, 64, 64));
    }
    other.flush();
    root.set_time(f, 0.5 * f);
    root.checkpoint(f + 1);
  }
  other.finalize();
  root.finalize(5);
  expect_continued(dir.path, m);
}

TEST(DatabaseResume, AnotherManifestIsRefusedNamingTheDifference) {
  TempDir dir;
  const Manifest m = sample_manifest(2, 2);
  write_interrupted(dir.path, m);
  Manifest size = m;
  size.image.width = 48;
  EXPECT_NE(error_of([&] { DatabaseWriter::resume(dir.path, size); }).find("the image size ([image] width, height) differs"),
            std::string::npos);
  Manifest tasks = m;
  tasks.tasks[1].parameters["isovalue"] = 0.75;
  const std::string t = error_of([&] { DatabaseWriter::resume(dir.path, tasks); });
  EXPECT_NE(t.find("cannot resume this database: task 1"), std::string::npos) << t;
  Manifest cams = m;
  cams.cameras[1].position.x += 0.5;
  EXPECT_NE(error_of([&] { DatabaseWriter::resume(dir.path, cams); }).find("camera 1 differs"), std::string::npos);
  Manifest video = m;
  video.video.crf = 30;
  EXPECT_NE(error_of([&] { DatabaseWriter::resume(dir.path, video); }).find("the video settings"), std::string::npos);
  // Refusals change nothing: the right manifest still resumes the 3 checkpointed frames.
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.frame_count(), 3);
  DatabaseWriter w = DatabaseWriter::resume(dir.path, m);
  EXPECT_EQ(w.manifest().frames_written, 3);
}

TEST(DatabaseResume, NoDatabaseIsCreatedAfresh) {
  TempDir dir;
  const Manifest m = sample_manifest(2, 2);
  DatabaseWriter w = DatabaseWriter::resume(dir / "new", m);
  EXPECT_EQ(w.manifest().frames_written, 0);
  append_snapshot(w, m, 0);
  w.finalize();
  EXPECT_EQ(Database::open(dir / "new").frame_count(), 1);
}

TEST(DatabaseResume, MovieShorterThanTheCheckpointIsRefused) {
  TempDir dir;
  const Manifest m = sample_manifest(2, 2);
  write_interrupted(dir.path, m);
  const fs::path movie = Database::open(dir.path).stream_path(1, 1);
  fs::resize_file(movie, fs::file_size(movie) / 3);  // lose the later fragments
  const std::string e = error_of([&] { DatabaseWriter::resume(dir.path, m); });
  EXPECT_NE(e.find(movie.string()), std::string::npos) << e;
  EXPECT_NE(e.find("cannot resume it"), std::string::npos) << e;
}

}  // namespace
