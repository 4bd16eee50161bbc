#include "web/mp4_fragments.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>

#include "core/error.hpp"
#include "web/database_json.hpp"
#include "web/fragment_index_cache.hpp"
#include "store/database.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"

namespace panoptes::web {
namespace {

namespace fs = std::filesystem;

fs::path make_db(const fs::path& dir, int frames, int gop) {
  store::SyntheticOptions o;
  o.cameras = 2;
  o.tasks = 1;
  o.frames = frames;
  o.width = 64;
  o.height = 48;
  o.video.gop = gop;
  o.threads = 1;
  store::write_synthetic_database(dir, o);
  return dir / "movies" / "c1" / "t0.mp4";
}

TEST(Mp4Fragments, OneFragmentPerGopCoversEveryFrame) {
  store::testing::TempDir tmp("web-frag");
  const fs::path movie = make_db(tmp.path / "db", 7, 3);
  const FragmentIndex index = index_fragments(movie);
  EXPECT_EQ(index.file_size, fs::file_size(movie));
  EXPECT_GT(index.init_size, 0u);
  ASSERT_EQ(index.fragments.size(), 3u);  // keyframes at 0, 3, 6
  EXPECT_EQ(index.frame_count(), 7);
  int expected_first = 0;
  std::uint64_t expected_offset = index.init_size;
  for (const auto& f : index.fragments) {
    EXPECT_EQ(f.first_frame, expected_first);
    EXPECT_EQ(f.offset, expected_offset);  // fragments follow each other with nothing between
    expected_first += f.frames;
    expected_offset += f.size;
  }
  EXPECT_EQ(index.fragments[2].frames, 1);
  EXPECT_LE(expected_offset, index.file_size);  // a finished movie ends with an mfra box
}

TEST(Mp4Fragments, HostileSampleCountIsRefusedNotOverflowed) {
  store::testing::TempDir tmp("web-frag");
  const fs::path movie = make_db(tmp.path / "db", 3, 1);
  std::string bytes;
  {
    std::ifstream in(movie, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t trun = bytes.find("trun");
  ASSERT_NE(trun, std::string::npos);
  for (int i = 0; i < 4; ++i) bytes[trun + 8 + i] = char(0xff);  // sample_count after version + flags
  {
    std::ofstream out(movie, std::ios::binary | std::ios::trunc);
    out << bytes;
  }
  try {
    index_fragments(movie);
    FAIL() << "a trun count of 2^32-1 was accepted";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("4294967295 samples"), std::string::npos) << e.what();
  }
}

TEST(Mp4Fragments, TruncatedMovieKeepsItsCompleteFragments) {
  store::testing::TempDir tmp("web-frag");
  const fs::path movie = make_db(tmp.path / "db", 4, 1);
  const FragmentIndex whole = index_fragments(movie);
  ASSERT_EQ(whole.fragments.size(), 4u);
  fs::resize_file(movie, whole.fragments[3].offset + whole.fragments[3].size / 2);
  const FragmentIndex cut = index_fragments(movie);
  EXPECT_EQ(cut.fragments.size(), 3u);
  EXPECT_EQ(cut.frame_count(), 3);
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

/// A box header with a 64-bit size (size field 1, then the largesize).
std::string large_box(const char* type, std::uint64_t size) {
  std::string b = {0, 0, 0, 1};
  b += std::string(type, 4);
  for (int i = 7; i >= 0; --i) b += char((size >> (8 * i)) & 0xff);
  return b;
}

// Issue 31 row 7: a 64-bit box size of 2^64-16 wrapped the walk's offset back by 16 bytes, so the
// indexer (serve's /api/index, export-web) looped forever. Before the fix this test hung until ctest's
// timeout; now each case ends at once, top level (a box cut short: the fragments before it stay) and
// inside a moof (an error naming the box).
TEST(Mp4Fragments, WrappingBoxSizesEndTheWalk) {
  store::testing::TempDir tmp("web-frag");
  const fs::path movie = make_db(tmp.path / "db", 4, 1);
  const std::string good = read_bytes(movie);
  const FragmentIndex whole = index_fragments(movie);
  ASSERT_EQ(whole.fragments.size(), 4u);
  const std::uint64_t wrap = ~std::uint64_t(15);  // 2^64 - 16

  // Top level, between the second and the third fragment, after a 16-byte box: the wrapped offset
  // landed on that box again, and again.
  const std::size_t third = whole.fragments[2].offset;
  const std::string pad = std::string{0, 0, 0, 16} + "free" + std::string(8, '\0');
  write_bytes(movie, good.substr(0, third) + pad + large_box("free", wrap) + good.substr(third));
  const auto start = std::chrono::steady_clock::now();
  const FragmentIndex cut = index_fragments(movie);
  EXPECT_EQ(cut.fragments.size(), 2u);
  // Sizes 2^64 - 8k for every small k, and one that overhangs by a byte: all end the walk.
  for (std::uint64_t size : {wrap, ~std::uint64_t(7), std::uint64_t(good.size() - third + 17)}) {
    write_bytes(movie, good.substr(0, third) + pad + large_box("free", size) + good.substr(third));
    EXPECT_EQ(index_fragments(movie).fragments.size(), 2u) << size;
  }

  // Inside a moof: a traf whose size wraps is an error, not a loop.
  const std::size_t traf = good.find("traf", whole.fragments[1].offset) - 4;
  ASSERT_LT(traf, whole.fragments[1].offset + whole.fragments[1].size);
  std::string bytes = good;
  bytes.replace(traf, 4, std::string("\xff\xff\xff\xf0", 4));  // 32-bit size beyond the moof's end
  write_bytes(movie, bytes);
  try {
    index_fragments(movie);
    FAIL() << "a traf overhanging its moof was accepted";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("beyond its parent's end"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(Mp4Fragments, RefusesFilesThatAreNotMovies) {
  store::testing::TempDir tmp("web-frag");
  const fs::path junk = tmp.path / "junk.mp4";
  std::ofstream(junk) << "this is not a movie, just some text long enough to look like boxes";
  EXPECT_THROW(index_fragments(junk), FileError);
  EXPECT_THROW(index_fragments(tmp.path / "missing.mp4"), FileError);
  // A second moov after a fragment (the fuzzer's find): the init segment would swallow the fragment.
  const fs::path movie = make_db(tmp.path / "db", 2, 1);
  const std::string good = read_bytes(movie);
  const std::size_t moov = good.find("moov") - 4, moof = good.find("moof") - 4;
  const std::size_t second = index_fragments(movie).fragments[1].offset;
  write_bytes(movie, good.substr(0, second) + good.substr(moov, moof - moov) + good.substr(second));
  try {
    index_fragments(movie);
    FAIL() << "a second moov was accepted";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("a second moov box"), std::string::npos) << e.what();
  }
}

TEST(FragmentIndexCache, ReindexesOnlyWhenSizeOrMtimeChange) {
  store::testing::TempDir tmp("web-frag");
  const fs::path movie = make_db(tmp.path / "db", 4, 1);
  FragmentIndexCache cache;
  const auto first = cache.json(movie);
  EXPECT_EQ(*first, fragment_index_json(index_fragments(movie)).dump());
  EXPECT_EQ(cache.json(movie), first);  // the same text, not rebuilt
  EXPECT_EQ(cache.hits(), 1u);
  EXPECT_EQ(cache.misses(), 1u);
  // A movie being written grows: the next request sees its new fragment count.
  const FragmentIndex whole = index_fragments(movie);
  fs::resize_file(movie, whole.fragments[3].offset + whole.fragments[3].size / 2);
  const auto cut = cache.json(movie);
  EXPECT_EQ(cache.misses(), 2u);
  EXPECT_NE(*cut, *first);
  EXPECT_EQ(*cut, fragment_index_json(index_fragments(movie)).dump());
  // Same size, other mtime (a rewrite in place): rebuilt too.
  fs::last_write_time(movie, fs::last_write_time(movie) - std::chrono::seconds(10));
  cache.json(movie);
  EXPECT_EQ(cache.misses(), 3u);
  EXPECT_THROW(cache.json(tmp.path / "missing.mp4"), FileError);
}

TEST(FragmentIndexCache, StaysWithinItsByteBound) {
  store::testing::TempDir tmp("web-frag");
  make_db(tmp.path / "db", 4, 1);
  const fs::path a = tmp.path / "db" / "movies" / "c0" / "t0.mp4", b = tmp.path / "db" / "movies" / "c1" / "t0.mp4";
  FragmentIndexCache cache(1);  // room for one entry only
  cache.json(a);
  cache.json(b);  // evicts a
  cache.json(a);
  EXPECT_EQ(cache.misses(), 3u);
  EXPECT_EQ(cache.hits(), 0u);
}

}  // namespace
}  // namespace panoptes::web
