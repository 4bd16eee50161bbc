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

TEST(Mp4Fragments, RefusesFilesThatAreNotMovies) {
  store::testing::TempDir tmp("web-frag");
  const fs::path junk = tmp.path / "junk.mp4";
  std::ofstream(junk) << "this is not a movie, just some text long enough to look like boxes";
  EXPECT_THROW(index_fragments(junk), FileError);
  EXPECT_THROW(index_fragments(tmp.path / "missing.mp4"), FileError);
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
