// Writer + reader round trips: exact random access, sequential decode, truncation, crash safety,
// odd sizes, bad input.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "video/intra_encoder_pool.hpp"
#include "video/movie_reader.hpp"
#include "video/movie_test_util.hpp"
#include "video/movie_writer.hpp"

namespace panoptes::video {
namespace {

namespace fs = std::filesystem;
using testing::make_test_frame;
using testing::read_test_frame_number;

// A fresh directory per test, removed afterwards.
class MovieTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("panoptes_video_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  // Writes `frames` stamped test frames and closes the movie.
  void write_movie(const std::string& path, int w, int h, int frames, VideoSettings s = {}) {
    MovieWriter writer(path, w, h, s);
    for (int i = 0; i < frames; ++i) writer.append(make_test_frame(w, h, i));
    writer.close();
  }

  fs::path dir_;
};

template <class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

class GopRoundTrip : public MovieTest, public ::testing::WithParamInterface<int> {};

// Every frame, read in shuffled order, is the right frame and close to its source.
TEST_P(GopRoundTrip, ShuffledRandomAccessReturnsTheExactFrame) {
  const int gop = GetParam(), w = 320, h = 240, n = 45;
  VideoSettings s;
  s.gop = gop;
  const std::string path = file("gop.mp4");
  write_movie(path, w, h, n, s);

  MovieReader reader(path);
  ASSERT_EQ(reader.frame_count(), n);
  EXPECT_EQ(reader.width(), w);
  EXPECT_EQ(reader.height(), h);
  for (int i = 0; i < n; ++i) EXPECT_EQ(reader.is_keyframe(i), i % gop == 0) << "frame " << i;

  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(1234 + gop));
  double worst = 1e9;
  YuvFrame yuv;
  for (int i : order) {
    const auto before = reader.packets_decoded();
    reader.read(i, yuv);
    // Random access decodes at most one GOP: from the keyframe at or before i up to i.
    EXPECT_LE(reader.packets_decoded() - before, i % gop + 1) << "frame " << i;
    EXPECT_EQ(yuv.index, i);
    const Image got = MovieReader::to_rgba(yuv);
    ASSERT_EQ(read_test_frame_number(got), i) << "asked for frame " << i;
    const double p = psnr(got, make_test_frame(w, h, i));
    worst = std::min(worst, p);
    EXPECT_GE(p, 38.0) << "frame " << i;
  }
  RecordProperty("worst_psnr_db", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(Gops, GopRoundTrip, ::testing::Values(1, 10, 30));

TEST_F(MovieTest, SequentialDecodeSendsOnePacketPerFrame) {
  const int w = 128, h = 96, n = 25;
  VideoSettings s;
  s.gop = 10;
  const std::string path = file("seq.mp4");
  write_movie(path, w, h, n, s);
  MovieReader reader(path);
  YuvFrame yuv;
  for (int i = 0; i < n; ++i) {
    reader.read(i, yuv);
    EXPECT_EQ(read_test_frame_number(MovieReader::to_rgba(yuv)), i);
  }
  EXPECT_EQ(reader.packets_decoded(), n);  // no seek, no frame decoded twice
  // Re-reading the current frame costs nothing; a jump forward inside the GOP decodes on.
  reader.read(n - 1, yuv);
  EXPECT_EQ(reader.packets_decoded(), n);
  reader.read(3, yuv);  // back: seek to keyframe 0, decode 0..3
  EXPECT_EQ(reader.packets_decoded(), n + 4);
  reader.read(7, yuv);  // forward in the same GOP: 4..7
  EXPECT_EQ(reader.packets_decoded(), n + 8);
  reader.read(21, yuv);  // forward past a keyframe: seek to 20, decode 20, 21
  EXPECT_EQ(reader.packets_decoded(), n + 10);
  EXPECT_EQ(read_test_frame_number(MovieReader::to_rgba(yuv)), 21);
}

TEST_F(MovieTest, FpsDurationAndRgbaOutput) {
  VideoSettings s;
  s.fps = 25;
  const std::string path = file("fps.mp4");
  {
    MovieWriter writer(path, 160, 120, s);
    for (int i = 0; i < 10; ++i) writer.append(make_test_frame(160, 120, i, 4));  // RGBA input
    EXPECT_EQ(writer.frames_written(), 10);
  }  // the destructor closes
  MovieReader reader(path);
  EXPECT_EQ(reader.frame_count(), 10);
  EXPECT_NEAR(reader.fps(), 25.0, 1e-6);
  EXPECT_NEAR(reader.duration(), 0.4, 1e-6);
  const Image img = reader.read_rgba(7);
  EXPECT_EQ(img.channels, 4);
  EXPECT_EQ(read_test_frame_number(img), 7);
  EXPECT_GE(psnr(img, make_test_frame(160, 120, 7, 4)), 38.0);
}

// flush() in the middle of a GOP, with one or two (slice) threads: no frame stays in the encoder.
TEST_F(MovieTest, FlushMakesFramesVisibleWhileWriting) {
  for (const auto& [gop, threads] : {std::pair{1, 1}, std::pair{10, 1}, std::pair{10, 2}}) {
    SCOPED_TRACE("gop " + std::to_string(gop) + ", threads " + std::to_string(threads));
    VideoSettings s;
    s.gop = gop;
    s.threads = threads;
    const std::string path = file("live.mp4");
    MovieWriter writer(path, 96, 64, s);
    for (int i = 0; i < 7; ++i) writer.append(make_test_frame(96, 64, i));
    writer.flush();
    {
      MovieReader reader(path);
      ASSERT_EQ(reader.frame_count(), 7);
      EXPECT_EQ(read_test_frame_number(reader.read_rgba(6)), 6);
    }
    for (int i = 7; i < 12; ++i) writer.append(make_test_frame(96, 64, i));
    writer.flush();
    MovieReader reader(path);
    ASSERT_EQ(reader.frame_count(), 12);
    for (int i : {11, 0, 8, 7}) EXPECT_EQ(read_test_frame_number(reader.read_rgba(i)), i);
    // flush() did not have to drain and reopen the encoder: keyframes stay at multiples of the GOP
    // (an x264 that held a frame back made frame 7 a keyframe, so in situ, flushing every snapshot,
    // no movie ever had a P-frame).
    for (int i = 0; i < 12; ++i) EXPECT_EQ(reader.is_keyframe(i), i % gop == 0) << "frame " << i;
  }
}

TEST_F(MovieTest, TruncatedMovieYieldsItsFirstFrames) {
  const int n = 40;
  VideoSettings s;
  s.gop = 10;
  const std::string path = file("full.mp4"), cut = file("cut.mp4");
  write_movie(path, 160, 120, n, s);
  fs::copy_file(path, cut);
  fs::resize_file(cut, fs::file_size(path) / 2);
  MovieReader reader(cut);
  ASSERT_GT(reader.frame_count(), 0);
  ASSERT_LT(reader.frame_count(), n);
  for (int i = reader.frame_count() - 1; i >= 0; --i)
    EXPECT_EQ(read_test_frame_number(reader.read_rgba(i)), i) << "frame " << i;
  EXPECT_THROW(reader.read_rgba(reader.frame_count()), Error);
}

// Every cut point of a small movie: it opens (or is refused with FileError if even the header is
// gone) and whatever frames it reports all decode to the right frame.
TEST_F(MovieTest, EveryTruncationPointIsSafe) {
  for (int gop : {1, 4}) {
    SCOPED_TRACE("gop " + std::to_string(gop));
    const std::string path = file("full.mp4"), cut = file("cut.mp4");
    VideoSettings s;
    s.gop = gop;
    write_movie(path, 64, 48, 12, s);
    const auto size = fs::file_size(path);
    int last_count = 0;
    for (std::uintmax_t len = 0; len <= size; len += std::max<std::uintmax_t>(1, size / 97)) {
      fs::remove(cut);
      fs::copy_file(path, cut);
      fs::resize_file(cut, len);
      try {
        MovieReader reader(cut);
        EXPECT_GE(reader.frame_count(), last_count) << "length " << len;
        last_count = reader.frame_count();
        for (int i = 0; i < reader.frame_count(); ++i)
          ASSERT_EQ(read_test_frame_number(reader.read_rgba(i)), i) << "length " << len << " frame " << i;
      } catch (const FileError& e) {
        EXPECT_EQ(last_count, 0) << "a longer file must not become unreadable: " << e.what();
      }
    }
    fs::remove(cut);
    fs::copy_file(path, cut);
    EXPECT_EQ(MovieReader(cut).frame_count(), 12);
    fs::remove(cut);
    fs::remove(path);
  }
}

TEST_F(MovieTest, KilledWriterLeavesFlushedFramesReadable) {
  const std::string path = file("killed.mp4");
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(ready[0]);
    try {
      VideoSettings s;
      s.gop = 10;
      MovieWriter writer(path, 128, 96, s);
      for (int i = 0; i < 15; ++i) writer.append(make_test_frame(128, 96, i));
      writer.flush();
      for (int i = 15; i < 18; ++i) writer.append(make_test_frame(128, 96, i));  // not flushed
      const char c = 'x';
      if (write(ready[1], &c, 1) != 1) _exit(3);
      pause();  // killed here, with an unfinished fragment and no trailer
    } catch (...) {
      _exit(2);
    }
    _exit(1);
  }
  close(ready[1]);
  char c = 0;
  ASSERT_EQ(read(ready[0], &c, 1), 1) << "the writer child failed before flushing";
  close(ready[0]);
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));

  MovieReader reader(path);
  ASSERT_GE(reader.frame_count(), 15);
  std::vector<int> order(reader.frame_count());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  for (int i : order) EXPECT_EQ(read_test_frame_number(reader.read_rgba(i)), i);
}

TEST_F(MovieTest, OddSizesArePaddedAndCropped) {
  const int w = 201, h = 157, n = 6;
  const std::string path = file("odd.mp4");
  {
    MovieWriter writer(path, w, h);
    EXPECT_EQ(writer.padded_width(), 202);
    EXPECT_EQ(writer.padded_height(), 158);
    EXPECT_EQ(writer.width(), w);
    for (int i = 0; i < n; ++i) writer.append(make_test_frame(w, h, i));
  }
  MovieReader reader(path);
  EXPECT_EQ(reader.coded_width(), 202);
  EXPECT_EQ(reader.coded_height(), 158);
  reader.set_crop(w, h);
  EXPECT_EQ(reader.width(), w);
  YuvFrame yuv;
  reader.read(4, yuv);
  EXPECT_EQ(yuv.width, w);
  EXPECT_EQ(yuv.height, h);
  EXPECT_EQ(yuv.y.size(), std::size_t(w * h));
  EXPECT_EQ(yuv.u.size(), std::size_t(101 * 79));
  EXPECT_EQ(yuv.v.size(), std::size_t(101 * 79));
  for (int i = n - 1; i >= 0; --i) {
    const Image img = reader.read_rgba(i);
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    EXPECT_EQ(read_test_frame_number(img), i);
    EXPECT_GE(psnr(img, make_test_frame(w, h, i)), 38.0);
  }
  EXPECT_NE(error_message([&] { reader.set_crop(203, 157); }).find("does not fit the coded size 202x158"),
            std::string::npos);
}

TEST_F(MovieTest, TinyOddSizeWorks) {
  const std::string path = file("tiny.mp4");
  {
    MovieWriter writer(path, 1, 1);
    Image px(1, 1, 3);
    px.pixels = {200, 100, 50};
    writer.append(px);
  }
  MovieReader reader(path);
  reader.set_crop(1, 1);
  const Image img = reader.read_rgba(0);
  ASSERT_EQ(img.width, 1);
  EXPECT_NEAR(img.pixels[0], 200, 6);
  EXPECT_NEAR(img.pixels[1], 100, 6);
  EXPECT_NEAR(img.pixels[2], 50, 6);
}

TEST_F(MovieTest, WrongFrameSizeIsAnErrorNamingBothSizes) {
  const std::string path = file("wrong.mp4");
  MovieWriter writer(path, 64, 48);
  writer.append(make_test_frame(64, 48, 0));
  const std::string msg = error_message([&] { writer.append(make_test_frame(48, 64, 1)); });
  EXPECT_NE(msg.find("frame is 48x64, expected 64x48"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  Image gray(64, 48, 1);
  EXPECT_NE(error_message([&] { writer.append(gray); }).find("1 channels"), std::string::npos);
  writer.append(make_test_frame(64, 48, 1));  // the movie is still fine
  writer.close();
  EXPECT_NE(error_message([&] { writer.append(make_test_frame(64, 48, 2)); }).find("append after close"),
            std::string::npos);
  MovieReader reader(path);
  EXPECT_EQ(reader.frame_count(), 2);
  EXPECT_EQ(read_test_frame_number(reader.read_rgba(1)), 1);
}

TEST_F(MovieTest, BadSettingsAndSizesAreRefused) {
  VideoSettings s;
  s.preset = "nope";
  EXPECT_THROW(MovieWriter(file("a.mp4"), 64, 48, s), Error);
  EXPECT_NE(error_message([&] { MovieWriter(file("b.mp4"), 0, 48); }).find("frame size 0x48"), std::string::npos);
}

TEST_F(MovieTest, UncreatableFileIsAFileError) {
  const std::string path = file("no/such/dir/m.mp4");
  try {
    MovieWriter writer(path, 64, 48);
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), path);
  }
}

TEST_F(MovieTest, FullDiskIsAFileErrorNotACrash) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "/dev/full is absent";
  try {
    MovieWriter writer("/dev/full", 64, 48);
    for (int i = 0; i < 3; ++i) writer.append(make_test_frame(64, 48, i));
    writer.flush();
    FAIL() << "writing to /dev/full did not fail";
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), "/dev/full");
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
}

// A disk that fills up mid-movie (simulated with RLIMIT_FSIZE in a child): append/flush throw a
// FileError naming the file, the writer is destroyed without crashing, and the frames flushed
// before the failure still read.
TEST_F(MovieTest, DiskFullMidMovieKeepsFlushedFrames) {
  const std::string path = file("full_disk.mp4");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    signal(SIGXFSZ, SIG_IGN);  // writes past the limit fail with EFBIG instead of killing us
    struct rlimit limit {};
    limit.rlim_cur = limit.rlim_max = 60000;
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(3);
    int flushed = 0;
    try {
      MovieWriter writer(path, 160, 120);
      for (int i = 0; i < 1000; ++i) {
        writer.append(make_test_frame(160, 120, i));
        writer.flush();
        flushed = i + 1;
      }
      _exit(1);  // the limit was never hit
    } catch (const FileError& e) {
      const bool named = std::string(e.what()).find(path) != std::string::npos && e.path() == path;
      _exit(named && flushed > 0 ? 0 : 2);
    } catch (...) {
      _exit(4);
    }
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0) << "1: no error, 2: error without the path or nothing flushed, 3/4: other";
  MovieReader reader(path);
  ASSERT_GT(reader.frame_count(), 0);
  for (int i = 0; i < reader.frame_count(); ++i) EXPECT_EQ(read_test_frame_number(reader.read_rgba(i)), i);
}

TEST_F(MovieTest, MissingAndNonMovieFilesAreFileErrors) {
  const std::string missing = file("missing.mp4");
  try {
    MovieReader r(missing);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), missing);
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
  const std::string text = file("text.mp4");
  std::ofstream(text) << "this is not a movie, just some text that is long enough to be probed\n";
  try {
    MovieReader r(text);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), text);
    EXPECT_NE(std::string(e.what()).find("not a readable movie"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MovieReader r(dir_.string()), FileError);
  const std::string empty = file("empty.mp4");
  std::ofstream(empty).close();
  EXPECT_THROW(MovieReader r(empty), FileError);
}

TEST_F(MovieTest, MovieKilledBeforeItsFirstFlushOpensEmpty) {
  const std::string path = file("empty_movie.mp4");
  MovieWriter writer(path, 64, 48);  // header written, no frame yet
  MovieReader reader(path);
  EXPECT_EQ(reader.frame_count(), 0);
  EXPECT_EQ(reader.duration(), 0.0);
  EXPECT_THROW(reader.read_rgba(0), Error);
}

TEST_F(MovieTest, MovieWithoutVideoIsAFileError) {
  if (std::system("command -v ffmpeg > /dev/null 2>&1") != 0) GTEST_SKIP() << "ffmpeg is not installed";
  const std::string path = file("audio.mp4");
  const std::string cmd = "ffmpeg -v error -f lavfi -i anullsrc=r=8000 -t 0.2 -c:a aac '" + path + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  try {
    MovieReader r(path);
    FAIL() << "an audio-only file opened as a movie";
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), path);
    EXPECT_NE(std::string(e.what()).find("has no video stream"), std::string::npos) << e.what();
  }
}

// Corrupted P-frame data (issue #15): the decoder conceals it and used to hand the concealed picture
// out as good, sometimes with another frame's content. Every frame is now either exactly the frame
// asked for, or DamagedFrameError/Error; and the damage is reported, not hidden.
TEST_F(MovieTest, ConcealedFramesAreReportedNeverShownAsGood) {
  VideoSettings s;
  s.gop = 30;
  const std::string path = file("damaged.mp4");
  write_movie(path, 96, 64, 30, s);
  // Flip bytes inside the mdat (the coded pictures), well after the keyframe.
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto mdat = bytes.find("mdat");
  ASSERT_NE(mdat, std::string::npos);
  const std::size_t start = mdat + (bytes.size() - mdat) / 2;
  for (std::size_t i = start; i < start + 24 && i < bytes.size(); ++i) bytes[i] = char(bytes[i] ^ 0x5a);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << bytes;
  }
  int good = 0, damaged = 0;
  for (int pass = 0; pass < 2; ++pass) {  // in order, then backwards (seeks)
    MovieReader r(path);
    ASSERT_EQ(r.frame_count(), 30);
    for (int k = 0; k < r.frame_count(); ++k) {
      const int i = pass == 0 ? k : r.frame_count() - 1 - k;
      try {
        const Image img = r.read_rgba(i);
        EXPECT_EQ(read_test_frame_number(img), i) << "frame " << i << " shown with the wrong content";
        ++good;
      } catch (const Error& e) {
        ++damaged;
      }
    }
  }
  EXPECT_GT(damaged, 0) << "the damage went unreported";
  EXPECT_GT(good, 0) << "frames before the damage must stay readable";
}

TEST_F(MovieTest, OutOfRangeReadIsAnError) {
  const std::string path = file("range.mp4");
  write_movie(path, 64, 48, 3);
  MovieReader reader(path);
  const std::string msg = error_message([&] { reader.read_rgba(3); });
  EXPECT_NE(msg.find("frame 3 is out of range (the movie has 3 frames)"), std::string::npos) << msg;
  EXPECT_THROW(reader.read_rgba(-1), Error);
  EXPECT_EQ(read_test_frame_number(reader.read_rgba(2)), 2);  // still usable
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Intra-only movies of one size and settings share x264 encoders instead of opening one per frame,
// and a movie does not depend on which encoder made which frame or on what the other movies wrote in
// between: written alone or interleaved with others, it decodes to the same pictures. (Its bytes may
// differ in two places that do not change a picture: the slice header's idr_pic_id, and a padding bit
// x264 takes from its own frame counter.)
TEST_F(MovieTest, IntraOnlyMoviesShareEncodersAndDecodeTheSame) {
  const int w = 96, h = 64, n = 5, movies = 12, mine = 7;
  VideoSettings s;
  s.crf = 31;  // settings no other test uses: this test's pool is its own
  const std::string alone = file("alone.mp4");
  write_movie(alone, w, h, n, s);
  {
    std::vector<std::unique_ptr<MovieWriter>> writers;
    for (int k = 0; k < movies; ++k) writers.push_back(std::make_unique<MovieWriter>(file("m" + std::to_string(k) + ".mp4"), w, h, s));
    auto pool = IntraEncoderPool::shared(w, h, s, "test");
    // Every writer gets frame i before any gets i + 1 (as the in-situ session appends), in an order
    // that changes from frame to frame; the other movies get other pictures.
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < movies; ++j) {
        const int k = (j * 5 + i * 3) % movies;
        writers[std::size_t(k)]->append(make_test_frame(w, h, k == mine ? i : 40 + k + i));
      }
    for (auto& wr : writers) wr->close();
    EXPECT_EQ(pool->encoders_opened(), 1);  // one frame at a time: one encoder for all 60 frames
  }
  MovieReader a(alone), b(file("m" + std::to_string(mine) + ".mp4"));
  ASSERT_EQ(b.frame_count(), n);
  for (int i = 0; i < n; ++i) {
    const Image x = a.read_rgba(i), y = b.read_rgba(i);
    EXPECT_EQ(read_test_frame_number(y), i);
    EXPECT_TRUE(x.pixels == y.pixels) << "frame " << i;
  }
  MovieReader other(file("m3.mp4"));
  EXPECT_EQ(read_test_frame_number(other.read_rgba(2)), 40 + 3 + 2);
  // x264's version SEI: once per movie, in its first packet, whichever encoder made that.
  for (const auto& path : {alone, file("m3.mp4")}) {
    const std::string bytes = file_bytes(path);
    std::size_t copies = 0;
    for (auto at = bytes.find("x264 - core"); at != std::string::npos; at = bytes.find("x264 - core", at + 1)) ++copies;
    EXPECT_EQ(copies, 1u) << path;
  }
}

std::string run(const std::string& cmd, int* status) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  std::string out;
  if (!p) {
    *status = -1;
    return out;
  }
  char buf[256];
  while (fgets(buf, sizeof buf, p)) out += buf;
  *status = pclose(p);
  return out;
}

// FFmpeg's own tools accept the movies (intra-only ones are made by a fresh encoder per frame) and
// decode every frame without a warning.
TEST_F(MovieTest, FfprobeAcceptsTheMovie) {
  if (std::system("command -v ffprobe > /dev/null 2>&1") != 0) GTEST_SKIP() << "ffprobe is not installed";
  for (int gop : {1, 5}) {
    SCOPED_TRACE("gop " + std::to_string(gop));
    const std::string path = file("probe" + std::to_string(gop) + ".mp4");
    VideoSettings s;
    s.gop = gop;
    write_movie(path, 160, 90, 12, s);
    int status = 0;
    std::string out = run("ffprobe -v error -count_packets -show_entries stream=codec_name,pix_fmt,width,height,"
                          "nb_read_packets -of csv=p=0 '" + path + "'", &status);
    EXPECT_EQ(status, 0) << out;
    EXPECT_EQ(out, "h264,160,90,yuv420p,12\n");
    // x264's version SEI is kept once, not in every frame of an intra-only movie.
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::size_t copies = 0;
    for (auto at = bytes.find("x264 - core"); at != std::string::npos; at = bytes.find("x264 - core", at + 1)) ++copies;
    EXPECT_EQ(copies, 1u);
    if (std::system("command -v ffmpeg > /dev/null 2>&1") == 0) {
      out = run("ffmpeg -v warning -i '" + path + "' -f null -", &status);
      EXPECT_EQ(status, 0) << out;
      EXPECT_EQ(out, "");
    }
  }
}

}  // namespace
}  // namespace panoptes::video
