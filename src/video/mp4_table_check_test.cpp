// Movies whose sample tables promise more than the file holds (issue #15): refused with a clear
// error naming the file, fast and without allocating what the tables ask for.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "video/movie_reader.hpp"
#include "video/movie_test_util.hpp"
#include "video/movie_writer.hpp"

namespace panoptes::video {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void spill(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// Peak resident memory since the last reset, in MiB; -1 where /proc does not offer the reset.
long reset_peak_rss() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.close();
  return clear ? 0 : -1;
}
long peak_rss_mib() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6)) / 1024;
  return -1;
}

struct Outcome {
  std::string message;   // "(no error)" if the movie opened
  std::string path;      // FileError::path()
  double seconds = 0;
  long peak_growth_mib = -1;
};

Outcome open_movie(const std::string& path) {
  Outcome o;
  o.message = "(no error)";
  // After the reset the peak is the current resident size: the baseline (the peak before it may
  // have been reached by an earlier test).
  const bool can_measure = reset_peak_rss() == 0;
  const long before = peak_rss_mib();
  const auto t0 = std::chrono::steady_clock::now();
  try {
    MovieReader reader(path);
  } catch (const FileError& e) {
    o.message = e.what();
    o.path = e.path();
  }
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (can_measure) o.peak_growth_mib = peak_rss_mib() - before;
  return o;
}

class Mp4TableCheck : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("panoptes_mp4_tables_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    good_ = (dir_ / "good.mp4").string();
    MovieWriter writer(good_, 64, 48);
    for (int i = 0; i < 6; ++i) writer.append(testing::make_test_frame(64, 48, i));
    writer.close();
    bytes_ = slurp(good_);
    for (std::size_t i = 4; i + 12 <= bytes_.size(); ++i)
      if (bytes_[i] == 't' && bytes_[i + 1] == 'r' && bytes_[i + 2] == 'u' && bytes_[i + 3] == 'n') {
        trun_ = i + 4;  // version/flags, then sample_count
        break;
      }
    ASSERT_GT(trun_, 0u) << "the writer's movie has no trun box (no longer fragmented?)";
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string with_trun(std::uint32_t flags, std::uint32_t count) {
    auto b = bytes_;
    for (int k = 0; k < 3; ++k) b[trun_ + 1 + k] = std::uint8_t(flags >> (16 - 8 * k));
    for (int k = 0; k < 4; ++k) b[trun_ + 4 + k] = std::uint8_t(count >> (24 - 8 * k));
    const std::string path = (dir_ / "hostile.mp4").string();
    spill(path, b);
    return path;
  }

  fs::path dir_;
  std::string good_;
  std::vector<std::uint8_t> bytes_;
  std::size_t trun_ = 0;
};

TEST_F(Mp4TableCheck, TheWritersMovieStillOpens) {
  MovieReader reader(good_);
  EXPECT_EQ(reader.frame_count(), 6);
}

// The fuzzer's 2 kB movie: a trun of 83,886,080 samples without per-sample fields made FFmpeg
// allocate 2.4-2.85 GB and run > 60 s. The same trick on a movie of ours is refused at once.
TEST_F(Mp4TableCheck, SamplesWithoutBytesAreRefusedFastInLittleMemory) {
  const std::string path = with_trun(0x000001, 0x05000000);  // data offset only: 0 bytes per sample
  const Outcome o = open_movie(path);
  EXPECT_EQ(o.path, path) << o.message;
  EXPECT_NE(o.message.find("'trun'"), std::string::npos) << o.message;
  EXPECT_NE(o.message.find("83886080 samples"), std::string::npos) << o.message;
  EXPECT_LT(o.seconds, 2.0);
  if (o.peak_growth_mib < 0) GTEST_SKIP() << "no /proc/self/clear_refs: memory not measured";
  EXPECT_LT(o.peak_growth_mib, 64) << "peak resident memory grew by " << o.peak_growth_mib << " MiB";
}

TEST_F(Mp4TableCheck, TableLongerThanItsBoxIsRefused) {
  const std::string path = with_trun(0x000301, 1000000);  // duration + size per sample: 8 MB of table
  const Outcome o = open_movie(path);
  EXPECT_EQ(o.path, path) << o.message;
  EXPECT_NE(o.message.find("declares 1000000 entries of 8 bytes"), std::string::npos) << o.message;
}

// A stream whose pictures (SPS) are far larger than its container says: a tiny file could otherwise
// make every packet a 35-Mpixel decode. The decoder refuses the pictures; the reader reports an error.
TEST_F(Mp4TableCheck, PicturesLargerThanTheContainerSaysAreNotDecoded) {
  const std::string big = (dir_ / "big.mp4").string();
  {
    MovieWriter writer(big, 512, 512);
    for (int i = 0; i < 2; ++i) writer.append(testing::make_test_frame(512, 512, i));
    writer.close();
  }
  auto b = slurp(big);
  std::size_t avc1 = 0;
  for (std::size_t i = 0; i + 32 <= b.size() && !avc1; ++i)
    if (b[i] == 'a' && b[i + 1] == 'v' && b[i + 2] == 'c' && b[i + 3] == '1') avc1 = i + 4;
  ASSERT_GT(avc1, 0u);
  ASSERT_EQ(b[avc1 + 24], 0x02);  // width 512, big-endian, 24 bytes into the sample entry
  b[avc1 + 24] = 0;
  b[avc1 + 25] = 32;  // the container now says 32x32
  b[avc1 + 26] = 0;
  b[avc1 + 27] = 32;
  const std::string path = (dir_ / "small_container.mp4").string();
  spill(path, b);
  MovieReader reader(path);
  EXPECT_EQ(reader.coded_width(), 32);
  YuvFrame frame;
  EXPECT_THROW(reader.read(0, frame), Error) << "a 512x512 picture was decoded for a 32x32 container";
}

#ifdef PANOPTES_FUZZ_REGRESSIONS
// The committed input itself (also replayed by fuzz.replay.movie and the sanitizer stage).
TEST(Mp4TableCheckRegression, FuzzerMovieIsRefusedFastInLittleMemory) {
  const std::string path = std::string(PANOPTES_FUZZ_REGRESSIONS) + "/movie/oom-2kB-mp4-allocates-2.8GB.mp4";
  ASSERT_TRUE(fs::exists(path)) << path;
  const Outcome o = open_movie(path);
  EXPECT_EQ(o.path, path) << o.message;
  EXPECT_NE(o.message.find("MP4 box 'trun' at byte 857 declares 83886080 samples"), std::string::npos) << o.message;
  EXPECT_LT(o.seconds, 2.0);
  if (o.peak_growth_mib < 0) GTEST_SKIP() << "no /proc/self/clear_refs: memory not measured";
  EXPECT_LT(o.peak_growth_mib, 64) << "peak resident memory grew by " << o.peak_growth_mib << " MiB";
}
#endif

}  // namespace
}  // namespace panoptes::video
