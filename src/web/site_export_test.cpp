// export-web of a packed database (issue 46): packs linked (or copied) into the site with their
// indexes, no file per stream, and a binary stream index whose entries name the same ranges as the
// database's own reading of the packs, damaged frames included.
#include "web/site_export.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "core/frame_stamp.hpp"
#include "store/database.hpp"
#include "web/server_test_support.hpp"
#include "web/stream_index.hpp"

namespace panoptes::web {
namespace {

namespace fs = std::filesystem;

ino_t inode(const fs::path& p) {
  struct stat st{};
  return ::stat(p.c_str(), &st) == 0 ? st.st_ino : 0;
}

TEST(SiteExport, PackedDatabaseBecomesPacksAndAStreamIndex) {
  store::testing::TempDir tmp{"site-export"};
  const fs::path db = tmp.path / "db", site = tmp.path / "site", player = tmp.path / "player";
  testing::write_packed_database(db, 3, 2, 3);
  fs::create_directories(player);
  std::ofstream(player / "index.html") << "<!doctype html>";
  const store::Database source = store::Database::open(db);
  // Frame 1 of stream (1, 0) damaged in the pack: a byte of its picture data flipped.
  const store::PackedStream hurt = source.packed_stream(1, 0);
  {
    std::fstream pack(hurt.pieces[2].file, std::ios::in | std::ios::out | std::ios::binary);
    pack.seekg(std::streamoff(hurt.pieces[2].offset + hurt.pieces[2].size - 8));
    const char c = char(pack.get() ^ 0x5a);
    pack.seekp(std::streamoff(hurt.pieces[2].offset + hurt.pieces[2].size - 8));
    pack.put(c);
  }
  const std::vector<int> damaged = source.damaged_frames(1, 0);
  ASSERT_FALSE(damaged.empty());

  const SiteExport summary = export_site(db, site, player, DatabaseCopy::copy, false);
  EXPECT_EQ(summary.streams, 6);
  EXPECT_EQ(summary.indexed, 6);
  EXPECT_FALSE(fs::exists(site / "api/index"));  // no file per stream
  const std::string pack = store::pack_file_name(0, 0);
  // Same file system: a hard link, no bytes copied for the pack.
  EXPECT_EQ(inode(site / "db/packs" / pack), inode(db / "packs" / pack));
  EXPECT_TRUE(fs::exists(site / "db/packs" / store::pack_index_name(0, 0)));

  const auto dbj = nlohmann::json::parse(testing::read_file(site / "api/database.json"));
  EXPECT_EQ(dbj["layout"], "packed");
  const auto& si = dbj["stream_index"];
  EXPECT_EQ(si["packs"], nlohmann::json::array({"db/packs/" + pack}));
  EXPECT_EQ(si["shards"], nlohmann::json::array({"api/streams/0.bin"}));
  EXPECT_EQ(si["entry_bytes"], stream_entry_bytes(3));
  EXPECT_EQ(si["header_bytes"], kStreamIndexHeaderBytes);
  EXPECT_EQ(si["streams_per_shard"], kStreamsPerShard);
  for (int s = 0; s < 6; ++s) {
    const store::PackedStream ps = source.packed_stream(s / 2, s % 2);
    const StreamIndexEntry e = read_stream_index_entry(site / "api/streams/0.bin", s);
    ASSERT_EQ(e.fragments.size(), ps.pieces.size() - 1) << "stream " << s;
    EXPECT_EQ(e.init.offset, ps.pieces[0].offset);
    EXPECT_EQ(e.init.size, ps.pieces[0].size);
    for (std::size_t k = 0; k < e.fragments.size(); ++k) {
      EXPECT_EQ(e.fragments[k].offset, ps.pieces[k + 1].offset);
      EXPECT_EQ(e.fragments[k].size, ps.pieces[k + 1].size);
      EXPECT_EQ(e.fragments[k].frames, 1u);
    }
    const std::vector<std::uint32_t> want = s == 2 ? std::vector<std::uint32_t>(damaged.begin(), damaged.end())
                                                   : std::vector<std::uint32_t>{};
    EXPECT_EQ(e.damaged, want) << "stream " << s;
  }
  // OUT/db is a database: the exported copy reads with its stamps.
  const store::Database copy = store::Database::open(site / "db");
  EXPECT_EQ(read_frame_stamp(copy.stream(2, 1)->read_rgba(2)), (FrameStamp{2, 1, 2}));
}

// --link: OUT/db is a link to the database, the stream index is written all the same.
TEST(SiteExport, PackedDatabaseLinkedKeepsItsStreamIndex) {
  store::testing::TempDir tmp{"site-export"};
  const fs::path db = tmp.path / "db", site = tmp.path / "site", player = tmp.path / "player";
  testing::write_packed_database(db, 2, 1, 2);
  fs::create_directories(player);
  std::ofstream(player / "index.html") << "<!doctype html>";
  const SiteExport summary = export_site(db, site, player, DatabaseCopy::link, false);
  EXPECT_EQ(summary.indexed, 2);
  EXPECT_EQ(summary.bytes_copied, 0);
  EXPECT_TRUE(fs::is_symlink(site / "db"));
  const auto dbj = nlohmann::json::parse(testing::read_file(site / "api/database.json"));
  EXPECT_EQ(dbj["stream_index"]["packs"], nlohmann::json::array({"db/packs/" + store::pack_file_name(0, 0)}));
  const StreamIndexEntry e = read_stream_index_entry(site / "api/streams/0.bin", 1);
  EXPECT_EQ(e.fragments.size(), 2u);
  EXPECT_TRUE(fs::exists(site / "db/packs" / store::pack_file_name(0, 0)));
}

}  // namespace
}  // namespace panoptes::web
