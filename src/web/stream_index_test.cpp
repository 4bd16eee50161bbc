// The static site's binary stream index (web/stream_index.hpp): entries at computed offsets, read
// back as written, and what the format cannot hold refused with the value named.
#include "web/stream_index.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "store/test_support.hpp"

namespace panoptes::web {
namespace {

namespace fs = std::filesystem;

TEST(StreamIndex, EntriesSitAtComputedOffsetsAndReadBackAsWritten) {
  store::testing::TempDir tmp{"stream-index"};
  const fs::path file = tmp.path / "1.bin";
  const int frames = 3;
  // Streams 10..13 of 20: a full one over two packs with a damaged frame, a missing one, two more.
  StreamIndexWriter w(file, 10, 4, 20, frames, 2);
  StreamIndexEntry full;
  full.init = {0, 0, 812, 0};
  full.fragments = {{0, 900, 150, 1}, {1, (std::uint64_t(1) << 40) + 7, 160, 2}};
  full.damaged = {2};
  w.add(full);
  w.add(StreamIndexEntry{});
  StreamIndexEntry one;
  one.init = {1, 0, 812, 0};
  one.fragments = {{1, 5000, 100, 1}, {1, 7000, 100, 1}, {1, 9000, 100, 1}};
  one.damaged = {0, 1};
  w.add(one);
  w.add(one);
  w.finish();
  EXPECT_EQ(fs::file_size(file), kStreamIndexHeaderBytes + 4 * stream_entry_bytes(frames) + 4 * 5);

  const StreamIndexEntry a = read_stream_index_entry(file, 10);
  ASSERT_EQ(a.fragments.size(), 2u);
  EXPECT_EQ(a.init.size, 812u);
  EXPECT_EQ(a.fragments[1].pack, 1u);
  EXPECT_EQ(a.fragments[1].offset, (std::uint64_t(1) << 40) + 7);
  EXPECT_EQ(a.fragments[1].frames, 2u);
  EXPECT_EQ(a.damaged, std::vector<std::uint32_t>{2});
  EXPECT_TRUE(read_stream_index_entry(file, 11).fragments.empty());
  const StreamIndexEntry c = read_stream_index_entry(file, 13);
  ASSERT_EQ(c.fragments.size(), 3u);
  EXPECT_EQ(c.fragments[2].offset, 9000u);
  EXPECT_EQ(c.damaged, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_THROW(read_stream_index_entry(file, 14), FileError);
  EXPECT_THROW(read_stream_index_entry(file, 9), FileError);
}

TEST(StreamIndex, RefusesWhatTheFormatCannotHold) {
  store::testing::TempDir tmp{"stream-index"};
  StreamIndexWriter w(tmp.path / "0.bin", 0, 1, 1, 1, 1);
  StreamIndexEntry two;
  two.fragments = {{0, 900, 10, 1}, {0, 910, 10, 1}};
  try {
    w.add(two);
    FAIL() << "more fragments than frames accepted";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("2 fragments"), std::string::npos) << e.what();
  }
  StreamIndexEntry far;
  far.fragments = {{0, std::uint64_t(1) << 48, 10, 1}};
  EXPECT_THROW(w.add(far), FileError);
  StreamIndexEntry other_pack;
  other_pack.fragments = {{1, 900, 10, 1}};
  EXPECT_THROW(w.add(other_pack), FileError);
  EXPECT_THROW(StreamIndexWriter(tmp.path / "1.bin", 0, 1, 1, 1, kStreamIndexMaxPacks + 1), FileError);
}

}  // namespace
}  // namespace panoptes::web
