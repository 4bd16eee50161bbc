// Frames never lie (issue #31, rows 5 and 6): a damaged first packet, a corrupted `tfdt`, a foreign or
// spliced movie are reported as damaged, never shown as good frames.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "video/movie_reader.hpp"
#include "video/movie_test_util.hpp"
#include "video/movie_writer.hpp"

namespace panoptes::video {
namespace {

namespace fs = std::filesystem;
using testing::make_test_frame;
using testing::read_test_frame_number;

constexpr int kW = 96, kH = 64, kFrames = 8;

MovieIdentity identity(std::uint8_t seed) {
  MovieIdentity id{};
  for (std::size_t i = 0; i < id.size(); ++i) id[i] = std::uint8_t(seed + i);
  return id;
}

struct Box {
  std::string type;
  std::size_t offset = 0, size = 0;
};

// Top-level boxes of an MP4 file (32-bit sizes: what our writer produces for small movies).
std::vector<Box> top_boxes(const std::string& bytes) {
  std::vector<Box> boxes;
  for (std::size_t pos = 0; pos + 8 <= bytes.size();) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + pos);
    const std::size_t size = std::size_t(p[0]) << 24 | std::size_t(p[1]) << 16 | std::size_t(p[2]) << 8 | p[3];
    if (size < 8 || pos + size > bytes.size()) break;
    boxes.push_back({bytes.substr(pos + 4, 4), pos, size});
    pos += size;
  }
  return boxes;
}

class FrameChecksTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("panoptes_frame_checks_" + std::string(info->name()) + "_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const MovieIdentity& id, int gop = 1, int frames = kFrames) {
    const std::string path = (dir_ / name).string();
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    EXPECT_GE(fd, 0);
    VideoSettings s;
    s.gop = gop;
    MovieWriter w(fd, path, kW, kH, s, id);
    for (int i = 0; i < frames; ++i) w.append(make_test_frame(kW, kH, i));
    w.close();
    return path;
  }
  static std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
  }
  static void spit(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  }

  // Reads every frame: counts the damaged ones and fails on a frame shown with another's content.
  static int damaged_frames(const std::string& path, const FrameChecks& checks, int* wrong = nullptr) {
    MovieReader r(path, checks);
    int damaged = 0, shown_wrong = 0;
    for (int i = 0; i < r.frame_count(); ++i) {
      try {
        if (read_test_frame_number(r.read_rgba(i)) != i) ++shown_wrong;
      } catch (const DamagedFrameError&) {
        ++damaged;
      }
    }
    if (wrong) *wrong = shown_wrong;
    return damaged;
  }

  fs::path dir_;
};

TEST_F(FrameChecksTest, StampedMoviesReadCleanWithTheirIdentity) {
  const std::string path = write("a.mp4", identity(1));
  const FrameChecks checks{true, identity(1)};
  int wrong = -1;
  EXPECT_EQ(damaged_frames(path, checks, &wrong), 0);
  EXPECT_EQ(wrong, 0);
  MovieReader r(path, checks);
  EXPECT_TRUE(r.check_frames().empty());
  // gop > 1 (the writer's own encoder, P-frames) is stamped the same way.
  EXPECT_EQ(damaged_frames(write("p.mp4", identity(1), 4), checks), 0);
}

TEST_F(FrameChecksTest, ADamagedFirstPacketDoesNotSwitchTheChecksOff) {
  const std::string path = write("a.mp4", identity(1));
  std::string bytes = slurp(path);
  const auto boxes = top_boxes(bytes);
  const auto first_mdat = std::find_if(boxes.begin(), boxes.end(), [](const Box& b) { return b.type == "mdat"; });
  ASSERT_NE(first_mdat, boxes.end());
  // One byte near the end of frame 0's picture: it still decodes, to wrong pixels.
  bytes[first_mdat->offset + first_mdat->size - 6] ^= 0x10;
  spit(path, bytes);
  // Without a recorded mode (an older database) and with one: frame 0 is damaged, the rest good.
  for (const FrameChecks& checks : {FrameChecks{}, FrameChecks{true, identity(1)}}) {
    int wrong = -1;
    EXPECT_EQ(damaged_frames(path, checks, &wrong), 1) << "required " << checks.required;
    EXPECT_EQ(wrong, 0);
    MovieReader r(path, checks);
    EXPECT_EQ(r.check_frames(), std::vector<int>{0});
  }
}

TEST_F(FrameChecksTest, ACorruptedTfdtNeverReordersFramesSilently) {
  const std::string path = write("a.mp4", identity(1));
  const std::string good = slurp(path);
  // Frame 0's fragment claims to start after the last frame: sorted by time it would play last.
  std::string bytes = good;
  const auto tfdt = bytes.find("tfdt");
  ASSERT_NE(tfdt, std::string::npos);
  const int version = static_cast<unsigned char>(bytes[tfdt + 4]);
  const std::size_t at = tfdt + 8 + (version == 1 ? 4 : 0);  // low 32 bits of baseMediaDecodeTime
  const std::uint32_t late = 1u << 24;
  for (int i = 0; i < 4; ++i) bytes[at + std::size_t(i)] = char(late >> (24 - 8 * i));
  spit(path, bytes);
  int wrong = -1;
  EXPECT_EQ(damaged_frames(path, FrameChecks{true, identity(1)}, &wrong), kFrames);
  EXPECT_EQ(wrong, 0) << "a frame was shown at another frame's index";
  // The legacy reading shows what the issue found: frames at the wrong index, all "ok".
  damaged_frames(path, FrameChecks{}, &wrong);
  EXPECT_GT(wrong, 0);

  // A fragment shifted by less than a frame keeps its place but not its time: damaged too.
  bytes = good;
  std::size_t pos = 0;
  for (int k = 0; k <= 3; ++k) pos = bytes.find("tfdt", pos + 1);
  const std::size_t at3 = pos + 8 + (static_cast<unsigned char>(bytes[pos + 4]) == 1 ? 4 : 0);
  bytes[at3 + 3] = char(bytes[at3 + 3] + 1);
  spit(path, bytes);
  MovieReader r(path, FrameChecks{true, identity(1)});
  EXPECT_EQ(r.check_frames(), std::vector<int>{3});
  try {
    YuvFrame frame;
    r.read(3, frame);
    ADD_FAILURE() << "frame 3 at the wrong time read as good";
  } catch (const DamagedFrameError& e) {
    EXPECT_NE(std::string(e.what()).find("timestamp"), std::string::npos) << e.what();
  }
}

TEST_F(FrameChecksTest, ForeignAndSplicedMoviesAreDamaged) {
  const std::string a = write("a.mp4", identity(1));
  const std::string b = write("b.mp4", identity(2));
  // Foreign: another movie's file in this one's place.
  EXPECT_EQ(damaged_frames(b, FrameChecks{true, identity(1)}), kFrames);
  {
    MovieReader r(b, FrameChecks{true, identity(1)});
    EXPECT_EQ(r.check_frames().size(), std::size_t(kFrames));
    try {
      r.read_rgba(0);
    } catch (const DamagedFrameError& e) {
      EXPECT_NE(std::string(e.what()).find("another movie"), std::string::npos) << e.what();
    }
  }
  // Spliced: a's first half, then b's fragments from the same frame on (timestamps continue).
  const std::string ab = slurp(a), bb = slurp(b);
  const auto boxes_a = top_boxes(ab), boxes_b = top_boxes(bb);
  std::string spliced;
  int fragments = 0;
  for (const Box& box : boxes_a) {
    if (box.type == "moof" && ++fragments > kFrames / 2) break;
    spliced += ab.substr(box.offset, box.size);
  }
  fragments = 0;
  for (const Box& box : boxes_b) {
    if (box.type == "moof") ++fragments;
    if (fragments > kFrames / 2 && (box.type == "moof" || box.type == "mdat")) spliced += bb.substr(box.offset, box.size);
  }
  const std::string path = (dir_ / "spliced.mp4").string();
  spit(path, spliced);
  MovieReader r(path, FrameChecks{true, identity(1)});
  ASSERT_EQ(r.frame_count(), kFrames);
  std::vector<int> expected;
  for (int f = kFrames / 2; f < kFrames; ++f) expected.push_back(f);
  EXPECT_EQ(r.check_frames(), expected);
  EXPECT_EQ(damaged_frames(path, FrameChecks{true, identity(1)}), kFrames / 2);
  EXPECT_EQ(damaged_frames(path, FrameChecks{}), 0);  // nothing recorded: nothing to tell them apart
}

TEST_F(FrameChecksTest, UnstampedMoviesFailRequiredChecks) {
  // A movie written without an identity (version-1 checksums) where the database records stamps.
  const std::string path = (dir_ / "v1.mp4").string();
  {
    MovieWriter w(path, kW, kH);
    for (int i = 0; i < 3; ++i) w.append(make_test_frame(kW, kH, i));
    w.close();
  }
  EXPECT_EQ(damaged_frames(path, FrameChecks{}), 0);
  EXPECT_EQ(damaged_frames(path, FrameChecks{true, identity(1)}), 3);
}

}  // namespace
}  // namespace panoptes::video
