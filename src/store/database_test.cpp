#include "store/database.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <numeric>
#include <random>

#include "core/error.hpp"
#include "core/frame_stamp.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
using namespace panoptes::store;
using panoptes::store::testing::sample_manifest;
using panoptes::store::testing::error_of;
using panoptes::store::testing::TempDir;
namespace fs = std::filesystem;

namespace {

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text) << "\nexpected: " << (part)

// Writes `frames` stamped snapshots of every stream and finalizes.
void write_db(const fs::path& dir, const Manifest& m, int frames, bool finalize = true) {
  DatabaseWriter w = DatabaseWriter::create(dir, m);
  for (int f = 0; f < frames; ++f) {
    for (int c = 0; c < m.camera_count(); ++c)
      for (int t = 0; t < m.task_count(); ++t)
        w.append(c, t, synthetic_frame(c, t, f, m.image.width, m.image.height));
    w.checkpoint();
  }
  if (finalize) w.finalize();
}

// Reads every frame of the stream in shuffled order and checks the stamps.
void expect_stamps(const Database& db, int camera, int task, int frames) {
  auto reader = db.stream(camera, task);
  ASSERT_GE(reader->frame_count(), frames);
  std::vector<int> order(static_cast<std::size_t>(frames));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(unsigned(camera * 31 + task)));
  for (int f : order) {
    const Image img = reader->read_rgba(f);
    ASSERT_EQ(img.width, db.manifest().image.width);
    ASSERT_EQ(img.height, db.manifest().image.height);
    const auto stamp = read_frame_stamp(img);
    ASSERT_TRUE(stamp.has_value()) << "camera " << camera << " task " << task << " frame " << f;
    EXPECT_EQ(*stamp, (FrameStamp{std::uint32_t(camera), std::uint32_t(task), std::uint32_t(f)}));
  }
}

}  // namespace

TEST(Database, WriteCheckpointFinalizeThenOpenAndReadStamps) {
  TempDir dir;
  Manifest m = sample_manifest(3, 2, 63, 37);  // odd size: padded to 64x38 and cropped back
  m.video.crf = 30;                               // the stamp must survive the highest supported CRF
  m.video.gop = 4;
  write_db(dir.path, m, 7);
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.status(), Status::complete);
  EXPECT_EQ(db.stored_status(), Status::complete);
  EXPECT_EQ(db.frame_count(), 7);
  EXPECT_EQ(db.manifest().image.padded_width, 64);
  EXPECT_EQ(db.manifest().image.padded_height, 38);
  EXPECT_EQ(db.stream_path(2, 1), dir.path / "movies/c2/t1.mp4");
  EXPECT_FALSE(fs::exists(dir.path / kLockFileName));
  for (int c = 0; c < 3; ++c)
    for (int t = 0; t < 2; ++t) expect_stamps(db, c, t, 7);
  const StreamReport report = db.validate_streams(2, true);
  EXPECT_EQ(report.checked, 6);
  EXPECT_TRUE(report.problems.empty());
  EXPECT_GT(report.bytes, 0);
}

TEST(Database, StampSurvivesAtThePapersFrameSize) {
  TempDir dir;
  Manifest m = sample_manifest(1, 1, 920, 896);
  m.video.crf = 30;
  write_db(dir.path, m, 3);
  expect_stamps(Database::open(dir.path), 0, 0, 3);
}

TEST(Database, CreateFillsCreationTimeAndHostWhenEmpty) {
  TempDir dir;
  Manifest m = sample_manifest(2, 1);
  m.provenance.created.clear();
  m.provenance.host.clear();
  auto w = DatabaseWriter::create(dir / "db", m, false);
  w.finalize();
  const Database db = Database::open(dir / "db");
  EXPECT_EQ(db.manifest().provenance.created.size(), 20u);  // e.g. 2026-11-21T22:40:00Z
  EXPECT_EQ(db.manifest().provenance.created.back(), 'Z');
  EXPECT_FALSE(db.manifest().provenance.host.empty());
  // Given values are kept.
  m.provenance.created = "2000-01-01T00:00:00Z";
  auto w2 = DatabaseWriter::create(dir / "db2", m, false);
  w2.finalize();
  EXPECT_EQ(Database::open(dir / "db2").manifest().provenance.created, "2000-01-01T00:00:00Z");
}

TEST(Database, OpenReadsTheManifestOnly) {
  TempDir dir;
  Manifest m = sample_manifest(50, 20);
  m.status = Status::complete;
  m.frames_written = 10;
  write_manifest_atomic(dir / kManifestFileName, m);  // no movie exists at all
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.stream_count(), 1000);
  EXPECT_EQ(db.status(), Status::complete);
  EXPECT_CONTAINS(error_of([&] { db.stream(3, 4); }), "movies/c3/t4.mp4: movie missing (stream camera 3, task 4)");
  EXPECT_CONTAINS(error_of([&] { db.stream(50, 0); }), "camera 50 out of range");
}

TEST(Database, NonDatabasesAreRefusedClearly) {
  TempDir dir;
  EXPECT_CONTAINS(error_of([&] { Database::open(dir / "nope"); }), "no such database directory");
  std::ofstream(dir / "file") << "x";
  EXPECT_CONTAINS(error_of([&] { Database::open(dir / "file"); }), "not a directory");
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "no manifest here (not a Panoptes database)");
  std::ofstream(dir / kManifestFileName) << "{\"schema_version\": 3}";
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "schema_version 3 is not supported");
}

TEST(Database, ExistingDatabaseIsRefusedUnlessOverwrite) {
  TempDir dir;
  write_db(dir.path, sample_manifest(2, 2), 2);
  const std::string msg = error_of([&] { DatabaseWriter::create(dir.path, sample_manifest(1, 1)); });
  EXPECT_CONTAINS(msg, "already holds a Panoptes database");
  EXPECT_CONTAINS(msg, "(WriterOptions::overwrite replaces it)");  // a C++ caller's option
  WriterOptions cli;
  cli.overwrite_option = "--overwrite";  // a command's (issue 44: synth-db named the C++ setting)
  const std::string cli_msg = error_of([&] { DatabaseWriter::create(dir.path, sample_manifest(1, 1), cli); });
  EXPECT_CONTAINS(cli_msg, "(--overwrite replaces it)");
  EXPECT_EQ(cli_msg.find("WriterOptions"), std::string::npos) << cli_msg;
  // Nothing was touched: the old database still reads.
  expect_stamps(Database::open(dir.path), 1, 1, 2);
}

TEST(Database, OverwriteReplacesTheOldMovieTree) {
  TempDir dir;
  write_db(dir.path, sample_manifest(3, 2), 2);
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, sample_manifest(1, 1), /*overwrite=*/true);
    w.append(0, 0, synthetic_frame(0, 0, 0, 64, 64));
    w.finalize();
  }
  EXPECT_FALSE(fs::exists(dir / "movies/c2/t1.mp4"));
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.stream_count(), 1);
  expect_stamps(db, 0, 0, 1);
}

TEST(Database, LiveWriterShowsRunningAndBlocksASecondWriter) {
  TempDir dir;
  DatabaseWriter w = DatabaseWriter::create(dir.path, sample_manifest(2, 1));
  EXPECT_TRUE(writer_is_alive(dir.path));
  EXPECT_EQ(Database::open(dir.path).status(), Status::running);
  EXPECT_CONTAINS(error_of([&] { DatabaseWriter::create(dir.path, sample_manifest(2, 1), true); }),
                  "another process is writing this database");
  w.finalize();
  EXPECT_FALSE(writer_is_alive(dir.path));
  EXPECT_EQ(Database::open(dir.path).status(), Status::complete);
}

TEST(Database, WrongFrameSizeIsRefusedAndEarlierFramesStayReadable) {
  TempDir dir;
  const Manifest m = sample_manifest(2, 1);
  DatabaseWriter w = DatabaseWriter::create(dir.path, m);
  for (int f = 0; f < 3; ++f) {
    for (int c = 0; c < 2; ++c) w.append(c, 0, synthetic_frame(c, 0, f, 64, 64));
    w.checkpoint();
  }
  EXPECT_CONTAINS(error_of([&] { w.append(1, 0, Image(48, 64, 4)); }),
                  "frame for camera 1, task 0 is 48x64, expected the database image size 64x64");
  EXPECT_CONTAINS(error_of([&] { w.append(1, 0, Image(64, 64, 1)); }), "1 channels, expected 3 or 4");
  EXPECT_CONTAINS(error_of([&] { w.append(2, 0, Image(64, 64, 4)); }), "camera 2 out of range");
  EXPECT_CONTAINS(error_of([&] { w.append(0, 1, Image(64, 64, 4)); }), "task 1 out of range");
  w.finalize();
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.frame_count(), 3);
  expect_stamps(db, 0, 0, 3);
  expect_stamps(db, 1, 0, 3);
  EXPECT_CONTAINS(error_of([&] { w.append(0, 0, Image(64, 64, 4)); }), "finalized");
}

TEST(Database, DestroyedWithoutFinalizeIsMarkedInterrupted) {
  TempDir dir;
  try {
    DatabaseWriter w = DatabaseWriter::create(dir.path, sample_manifest(2, 2));
    for (int f = 0; f < 2; ++f) {
      for (int c = 0; c < 2; ++c)
        for (int t = 0; t < 2; ++t) w.append(c, t, synthetic_frame(c, t, f, 64, 64));
      w.checkpoint();
    }
    w.append(0, 0, synthetic_frame(0, 0, 2, 64, 64));  // an incomplete third snapshot
    throw std::runtime_error("simulation blew up");
  } catch (const std::runtime_error&) {
  }
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.stored_status(), Status::interrupted);
  EXPECT_EQ(db.frame_count(), 2);
  expect_stamps(db, 1, 1, 2);
}

TEST(Database, BrokenStreamsGiveClearErrorsAndOthersStillRead) {
  TempDir dir;
  Manifest m = sample_manifest(2, 3);
  m.video.gop = 2;
  write_db(dir.path, m, 6);
  fs::remove(dir / "movies/c0/t1.mp4");
  fs::resize_file(dir / "movies/c1/t0.mp4", fs::file_size(dir / "movies/c1/t0.mp4") / 2);
  std::ofstream(dir / "movies/c1/t2.mp4", std::ios::trunc) << "this is not a movie\n";
  const Database db = Database::open(dir.path);
  EXPECT_CONTAINS(error_of([&] { db.stream(0, 1); }), "movies/c0/t1.mp4: movie missing (stream camera 0, task 1)");
  const std::string truncated = error_of([&] { db.stream(1, 0); });
  EXPECT_CONTAINS(truncated, "movies/c1/t0.mp4: truncated movie (stream camera 1, task 0): holds ");
  EXPECT_CONTAINS(truncated, "of the 6 frames the manifest records");
  EXPECT_CONTAINS(error_of([&] { db.stream(1, 2); }), "movies/c1/t2.mp4: not a readable movie (stream camera 1, task 2)");
  for (auto [c, t] : {std::pair{0, 0}, {0, 2}, {1, 1}}) expect_stamps(db, c, t, 6);

  const StreamReport report = db.validate_streams(2, true);
  EXPECT_EQ(report.checked, 6);
  ASSERT_EQ(report.problems.size(), 3u);
  EXPECT_EQ(report.problems[0].kind, StreamProblem::Kind::missing);
  EXPECT_EQ(report.problems[1].kind, StreamProblem::Kind::truncated);
  EXPECT_EQ(report.problems[2].kind, StreamProblem::Kind::unreadable);
  EXPECT_EQ(report.problems[2].camera, 1);
  EXPECT_EQ(report.problems[2].task, 2);
}

// A writer killed before its first checkpoint may leave a movie created but still empty (cli.kill_run
// met one: SIGKILL between creating the file and writing its header). With no frame recorded nothing
// is missing; once frames are recorded an empty movie is a problem.
TEST(Database, EmptyMovieOfADatabaseWithoutFramesIsNotAProblem) {
  TempDir dir;
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, sample_manifest(2, 1));
  }  // interrupted before the first checkpoint
  fs::create_directories(dir / "movies/c1");
  std::ofstream(dir / "movies/c1/t0.mp4", std::ios::trunc).close();
  ASSERT_TRUE(fs::exists(dir / "movies/c1/t0.mp4"));
  ASSERT_EQ(fs::file_size(dir / "movies/c1/t0.mp4"), 0u);
  const Database empty = Database::open(dir.path);
  ASSERT_EQ(empty.frame_count(), 0);
  EXPECT_TRUE(empty.validate_streams(1, true).problems.empty());

  TempDir dir2;
  write_db(dir2.path, sample_manifest(2, 1), 1);
  std::ofstream(dir2 / "movies/c1/t0.mp4", std::ios::trunc).close();
  const StreamReport report = Database::open(dir2.path).validate_streams(1, true);
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_EQ(report.problems[0].kind, StreamProblem::Kind::unreadable);
  EXPECT_CONTAINS(report.problems[0].message, "the file is empty");
}

TEST(Database, PathsLeavingTheDirectoryAreRefused) {
  TempDir outside("outside"), dir;
  write_db(dir.path, sample_manifest(3, 1), 2);
  // A movie replaced by a link to a file outside, and a camera directory linked outside.
  fs::copy_file(dir / "movies/c0/t0.mp4", outside / "stolen.mp4");
  fs::remove(dir / "movies/c0/t0.mp4");
  fs::create_symlink(outside / "stolen.mp4", dir / "movies/c0/t0.mp4");
  fs::create_directories(outside / "c1");
  fs::copy_file(dir / "movies/c1/t0.mp4", outside / "c1/t0.mp4");
  fs::remove_all(dir / "movies/c1");
  fs::create_symlink(outside / "c1", dir / "movies/c1");
  const Database db = Database::open(dir.path);
  EXPECT_CONTAINS(error_of([&] { db.stream(0, 0); }), "outside the database directory");
  EXPECT_CONTAINS(error_of([&] { db.stream(1, 0); }), "outside the database directory");
  expect_stamps(db, 2, 0, 2);
  const StreamReport report = db.validate_streams(1);
  ASSERT_EQ(report.problems.size(), 2u);
  EXPECT_EQ(report.problems[0].kind, StreamProblem::Kind::unsafe);
  EXPECT_EQ(report.problems[1].kind, StreamProblem::Kind::unsafe);

  // Manifests whose pattern escapes are refused at open time.
  Manifest m = read_manifest(dir / kManifestFileName);
  nlohmann::json j = to_json(m);
  j["movie_pattern"] = "../elsewhere/c{camera}/t{task}.mp4";
  std::ofstream(dir / kManifestFileName, std::ios::trunc) << j.dump();
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "reaches outside the database directory");
  j["movie_pattern"] = "/etc/c{camera}/t{task}.mp4";
  std::ofstream(dir / kManifestFileName, std::ios::trunc) << j.dump();
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "is absolute");
}

TEST(Database, InternalLinksAreAllowed) {
  TempDir dir;
  write_db(dir.path, sample_manifest(2, 1), 2);
  fs::create_directories(dir / "store");
  fs::rename(dir / "movies/c1/t0.mp4", dir / "store/real.mp4");
  fs::create_symlink("../../store/real.mp4", dir / "movies/c1/t0.mp4");
  expect_stamps(Database::open(dir.path), 1, 0, 2);
}

// Runs body in a forked child; returns its exit status. The child never returns into gtest.
template <class F>
int in_child(F body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    int code = 1;
    try {
      code = body();
    } catch (...) {
      code = 99;
    }
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST(Database, FullDiskSurfacesTheErrorAndKeepsTheManifestValid) {
  TempDir dir;
  Manifest m = sample_manifest(2, 1, 256, 256);
  m.video.crf = 0;  // lossless: noise frames are big, so a small file-size limit is hit quickly
  m.video.gop = 1;
  const fs::path message_file = dir / "child-message.txt";
  const fs::path db_dir = dir / "db";
  const int code = in_child([&] {
    DatabaseWriter w = DatabaseWriter::create(db_dir, m);
    // Movies may grow to 400 kB: a few frames fit, then writes fail with EFBIG instead of SIGXFSZ.
    ::signal(SIGXFSZ, SIG_IGN);
    rlimit limit{400 * 1024, 400 * 1024};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::mt19937 rng(3);
    Image frame(256, 256, 4);
    try {
      for (int f = 0; f < 200; ++f) {
        for (int c = 0; c < 2; ++c) {
          for (auto& p : frame.pixels) p = std::uint8_t(rng());
          draw_frame_stamp(frame, {std::uint32_t(c), 0, std::uint32_t(f)});
          w.append(c, 0, frame);
        }
        w.checkpoint();
      }
    } catch (const FileError& e) {
      std::ofstream(message_file) << e.what();
      return 0;
    }
    return 2;  // the limit was never hit
  });
  ASSERT_EQ(code, 0) << "child did not see a write error";
  std::ifstream in(message_file);
  const std::string message((std::istreambuf_iterator<char>(in)), {});
  EXPECT_CONTAINS(message, "movies/c");
  EXPECT_CONTAINS(message, "File too large");
  const Database db = Database::open(db_dir);
  EXPECT_EQ(db.status(), Status::interrupted);
  ASSERT_GT(db.frame_count(), 0);
  for (int c = 0; c < 2; ++c) {
    auto reader = db.stream(c, 0);
    for (int f = 0; f < db.frame_count(); ++f) {
      const auto stamp = read_frame_stamp(reader->read_rgba(f));
      ASSERT_TRUE(stamp.has_value());
      EXPECT_EQ(*stamp, (FrameStamp{std::uint32_t(c), 0, std::uint32_t(f)}));
    }
  }

  // A manifest write that fails (limit below its size) leaves the previous manifest intact.
  const int code2 = in_child([&] {
    ::signal(SIGXFSZ, SIG_IGN);
    rlimit limit{512, 512};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      write_manifest_atomic(db_dir / kManifestFileName, sample_manifest(20, 20));
    } catch (const FileError& e) {
      return std::string(e.what()).find("File too large") != std::string::npos ? 0 : 3;
    }
    return 2;
  });
  EXPECT_EQ(code2, 0);
  EXPECT_EQ(Database::open(db_dir).camera_count(), 2);
  int leftovers = 0;
  for (auto& e : fs::directory_iterator(db_dir)) leftovers += e.path().string().find(".tmp.") != std::string::npos;
  EXPECT_EQ(leftovers, 0);
}

// The same in the packed layout (issue 46): the pack write fails, the index never names the lost
// bytes, the manifest keeps the last checkpoint, and every checkpointed frame plays.
TEST(Database, FullDiskInThePackedLayoutKeepsTheCheckpoint) {
  TempDir dir;
  Manifest m = sample_manifest(2, 1, 256, 256);
  m.video.crf = 0;
  m.video.gop = 1;
  const fs::path message_file = dir / "child-message.txt";
  const fs::path db_dir = dir / "db";
  const int code = in_child([&] {
    WriterOptions o;
    o.layout = LayoutChoice::packed;
    DatabaseWriter w = DatabaseWriter::create(db_dir, m, o);
    ::signal(SIGXFSZ, SIG_IGN);
    rlimit limit{600 * 1024, 600 * 1024};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::mt19937 rng(3);
    Image frame(256, 256, 4);
    try {
      for (int f = 0; f < 200; ++f) {
        for (int c = 0; c < 2; ++c) {
          for (auto& p : frame.pixels) p = std::uint8_t(rng());
          draw_frame_stamp(frame, {std::uint32_t(c), 0, std::uint32_t(f)});
          w.append(c, 0, frame);
        }
        w.checkpoint();
      }
    } catch (const FileError& e) {
      std::ofstream(message_file) << e.what();
      try {
        w.checkpoint();  // refused: the pack would have a gap
        return 4;
      } catch (const FileError&) {
      }
      return 0;
    }
    return 2;
  });
  ASSERT_EQ(code, 0) << "child did not see a write error, or wrote after it";
  std::ifstream in(message_file);
  const std::string message((std::istreambuf_iterator<char>(in)), {});
  EXPECT_CONTAINS(message, "packs/s0-r0.pack");
  EXPECT_CONTAINS(message, "File too large");
  const Database db = Database::open(db_dir);
  EXPECT_EQ(db.status(), Status::interrupted);
  ASSERT_GT(db.frame_count(), 0);
  for (int c = 0; c < 2; ++c) {
    auto reader = db.stream(c, 0);
    for (int f = 0; f < db.frame_count(); ++f) {
      const auto stamp = read_frame_stamp(reader->read_rgba(f));
      ASSERT_TRUE(stamp.has_value());
      EXPECT_EQ(*stamp, (FrameStamp{std::uint32_t(c), 0, std::uint32_t(f)}));
    }
  }
  EXPECT_TRUE(db.validate_streams(1, true).problems.empty());
}

TEST(Database, KilledWriterLeavesAnInterruptedDatabaseWithItsCheckpointedFrames) {
  TempDir dir;
  const Manifest m = sample_manifest(3, 2);
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(ready[0]);
    try {
      DatabaseWriter w = DatabaseWriter::create(dir.path, m);
      for (int f = 0; f < 4; ++f) {
        for (int c = 0; c < 3; ++c)
          for (int t = 0; t < 2; ++t) w.append(c, t, synthetic_frame(c, t, f, 64, 64));
        w.checkpoint();
      }
      // A fifth snapshot half-written, never checkpointed, when the kill comes.
      w.append(0, 0, synthetic_frame(0, 0, 4, 64, 64));
      w.append(1, 1, synthetic_frame(1, 1, 4, 64, 64));
      const char ok = 'k';
      if (::write(ready[1], &ok, 1) != 1) ::_exit(3);
      while (true) ::pause();
    } catch (...) {
      ::_exit(2);
    }
  }
  ::close(ready[1]);
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1) << "writer child failed";
  ::close(ready[0]);
  EXPECT_EQ(Database::open(dir.path).status(), Status::running);  // still alive: reported as running
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));

  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.stored_status(), Status::running);
  EXPECT_EQ(db.status(), Status::interrupted);
  EXPECT_EQ(db.frame_count(), 4);
  for (int cam = 0; cam < 3; ++cam)
    for (int t = 0; t < 2; ++t) expect_stamps(db, cam, t, 4);
  EXPECT_TRUE(db.validate_streams(2, true).problems.empty());
}

TEST(Database, ThousandStreamsCreateAndOpen) {
  TempDir dir;
  SyntheticOptions o;
  o.cameras = 100;
  o.tasks = 10;
  o.frames = 2;
  o.video.gop = 2;
  const auto t0 = std::chrono::steady_clock::now();
  write_synthetic_database(dir.path, o);
  const auto t1 = std::chrono::steady_clock::now();
  const Database db = Database::open(dir.path);
  const auto t2 = std::chrono::steady_clock::now();
  EXPECT_EQ(db.stream_count(), 1000);
  EXPECT_EQ(db.status(), Status::complete);
  EXPECT_EQ(db.frame_count(), 2);
  EXPECT_LT(std::chrono::duration<double>(t2 - t1).count(), 0.2);
  std::mt19937 rng(5);
  for (int i = 0; i < 10; ++i) expect_stamps(db, int(rng() % 100), int(rng() % 10), 2);
  const StreamReport report = db.validate_streams();
  EXPECT_EQ(report.checked, 1000);
  EXPECT_TRUE(report.problems.empty());
  RecordProperty("create_seconds", std::to_string(std::chrono::duration<double>(t1 - t0).count()));
}
