// `--overwrite` removes exactly what the old manifest lists (issue #31, row 2): a user's file beside
// the movies, a link's target and a directory holding anything else survive.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "store/database.hpp"
#include "store/owned_files.hpp"
#include "store/safe_file.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
using namespace panoptes::store;
using panoptes::store::testing::sample_manifest;
using panoptes::store::testing::TempDir;
namespace fs = std::filesystem;

namespace {

std::string owned_slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void owned_spit(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
}

void make_database(const fs::path& dir, const std::string& pattern, int cameras, int tasks, bool overwrite = false) {
  Manifest m = sample_manifest(cameras, tasks, 32, 32);
  m.movie_pattern = pattern;
  DatabaseWriter w = DatabaseWriter::create(dir, m, overwrite);
  const Image img(32, 32, 3);
  for (int c = 0; c < cameras; ++c)
    for (int t = 0; t < tasks; ++t) w.append(c, t, img);
  w.finalize();
}

}  // namespace

TEST(OwnedFiles, OverwriteKeepsFilesTheDatabaseNeverWrote) {
  TempDir dir;
  make_database(dir.path, "holiday/c{camera}/t{task}.mp4", 3, 2);
  owned_spit(dir / "holiday/precious.txt", "precious\n");
  owned_spit(dir / "holiday/c1/notes.txt", "notes\n");
  owned_spit(dir / "holiday/c2/t7.mp4", "not listed: task 7 of 2\n");
  make_database(dir.path, "movies/c{camera}/t{task}.mp4", 1, 1, /*overwrite=*/true);
  EXPECT_EQ(owned_slurp(dir / "holiday/precious.txt"), "precious\n");
  EXPECT_EQ(owned_slurp(dir / "holiday/c1/notes.txt"), "notes\n");
  EXPECT_EQ(owned_slurp(dir / "holiday/c2/t7.mp4"), "not listed: task 7 of 2\n");
  EXPECT_FALSE(fs::exists(dir / "holiday/c1/t0.mp4"));
  EXPECT_FALSE(fs::exists(dir / "holiday/c0"));  // emptied: the directory the writer made goes too
  EXPECT_TRUE(fs::exists(dir / "movies/c0/t0.mp4"));
  EXPECT_EQ(Database::open(dir.path).stream_count(), 1);
}

TEST(OwnedFiles, OverwriteNeverFollowsALinkInTheOldTree) {
  TempDir dir, outside("outside");
  make_database(dir.path, "movies/c{camera}/t{task}.mp4", 2, 1);
  // movies/c1 replaced by a link to a directory of the user's that happens to hold a "t0.mp4".
  fs::remove_all(dir / "movies/c1");
  owned_spit(outside / "t0.mp4", "the user's own movie\n");
  fs::create_directory_symlink(outside.path, dir / "movies/c1");
  // movies/c0/t0.mp4 replaced by a link to a file of the user's: the link goes, the file stays.
  fs::remove(dir / "movies/c0/t0.mp4");
  owned_spit(outside / "keep.txt", "keep\n");
  fs::create_symlink(outside / "keep.txt", dir / "movies/c0/t0.mp4");
  make_database(dir.path, "other/{camera}_{task}.mp4", 1, 1, /*overwrite=*/true);
  EXPECT_EQ(owned_slurp(outside / "t0.mp4"), "the user's own movie\n");
  EXPECT_EQ(owned_slurp(outside / "keep.txt"), "keep\n");
  EXPECT_FALSE(fs::is_symlink(dir / "movies/c0/t0.mp4"));
  EXPECT_TRUE(fs::is_symlink(dir / "movies/c1"));  // not ours to remove: it is not a movie
}

TEST(OwnedFiles, FlatPatternsMatchOnlyListedIndices) {
  TempDir dir;
  owned_spit(dir / "3_1.mp4", "");
  owned_spit(dir / "3_10.mp4", "");   // task 10 of 2: not listed
  owned_spit(dir / "03_1.mp4", "");   // std::to_string never writes a leading zero
  owned_spit(dir / "3_1.mp4.bak", "");
  owned_spit(dir / "12_0.mp4", "");
  const FileHandle d = open_directory(dir.path);
  EXPECT_EQ(find_listed_movies(d.get(), "{camera}_{task}.mp4", 13, 2),
            (std::vector<std::string>{"12_0.mp4", "3_1.mp4"}));
  EXPECT_TRUE(find_listed_movies(d.get(), "{camera}_{task}.mp4", -1, 2).empty());
  // A camera named twice must agree with itself.
  owned_spit(dir / "c4/4-1.mp4", "");
  owned_spit(dir / "c4/5-1.mp4", "");
  EXPECT_EQ(find_listed_movies(d.get(), "c{camera}/{camera}-{task}.mp4", 10, 2),
            (std::vector<std::string>{"c4/4-1.mp4"}));
}

TEST(OwnedFiles, AnUnreadableOldManifestListsNothing) {
  TempDir dir;
  make_database(dir.path, "movies/c{camera}/t{task}.mp4", 2, 1);
  owned_spit(dir / kManifestFileName, "{ not json");
  make_database(dir.path, "new/c{camera}/t{task}.mp4", 1, 1, /*overwrite=*/true);
  EXPECT_TRUE(fs::exists(dir / "movies/c1/t0.mp4"));
  EXPECT_EQ(Database::open(dir.path).stream_count(), 1);
}
