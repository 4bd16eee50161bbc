#include "web/server.hpp"

#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <fstream>
#include <sstream>
#include <mutex>
#include <thread>
#include <chrono>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/frame_stamp.hpp"
#include "store/database.hpp"
#include "video/movie_reader.hpp"
#include "store/manifest.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"
#include "web/server_test_support.hpp"

namespace panoptes::web {
namespace {

namespace fs = std::filesystem;
using testing::Fixture;
using testing::options;
using testing::read_file;
using testing::Running;

TEST(Server, ServesDatabaseJsonIndexAndByteRanges) {
  Fixture f;
  std::vector<std::string> log;
  std::mutex log_mutex;
  auto o = options(f);
  o.log = [&](const std::string& line) {
    std::lock_guard lock(log_mutex);
    log.push_back(line);
  };
  Running r(o);
  httplib::Client c("127.0.0.1", r.server.port());
  auto res = c.Get("/api/database.json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  const auto db = nlohmann::json::parse(res->body);
  EXPECT_EQ(db["frames"], 5);
  EXPECT_EQ(db["playback_fps"], 12.5);
  EXPECT_EQ(db["cameras"]["count"], 3);
  EXPECT_EQ(db["tasks"].size(), 2u);
  // The cameras are in the database's binary table, which the player fetches as it is.
  EXPECT_FALSE(db.contains("graph"));
  const std::string table = db["cameras"]["table"];
  EXPECT_EQ(table, store::referenced_camera_table(o.database / store::kManifestFileName));
  res = c.Get("/db/" + table);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(std::uint64_t(res->body.size()), db["cameras"]["bytes"].get<std::uint64_t>());
  EXPECT_EQ(res->body.substr(0, 8), "PNPTCAMS");
  res = c.Get("/api/database.json?cameras=inline");
  ASSERT_TRUE(res);
  const auto inline_db = nlohmann::json::parse(res->body);
  EXPECT_EQ(inline_db["graph"].size(), 3u);
  EXPECT_EQ(inline_db["cameras"]["position"].size(), 9u);

  res = c.Get("/api/index/2/1.json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  const auto index = nlohmann::json::parse(res->body);
  ASSERT_EQ(index["fragments"].size(), 3u);  // gop 2, 5 frames
  EXPECT_EQ(index["fragments"][2][2], 4);    // first frame of the last fragment

  // The second fragment by a byte range: exactly those bytes, 206.
  const std::uint64_t offset = index["fragments"][1][0], size = index["fragments"][1][1];
  res = c.Get("/db/movies/c2/t1.mp4",
              {{"Range", "bytes=" + std::to_string(offset) + "-" + std::to_string(offset + size - 1)}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 206);
  EXPECT_EQ(res->body, read_file(f.db / "movies/c2/t1.mp4").substr(offset, size));
  res = c.Get("/db/movies/c2/t1.mp4");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->body.size(), fs::file_size(f.db / "movies/c2/t1.mp4"));
  // A link that stays inside the database is fine.
  res = c.Get("/db/movies/inside.mp4");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);

  res = c.Get("/");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_NE(res->body.find("player"), std::string::npos);

  // Out of range stream, missing movie, corrupt movie.
  EXPECT_EQ(c.Get("/api/index/3/0.json")->status, 404);
  fs::remove(f.db / "movies/c1/t0.mp4");
  EXPECT_EQ(c.Get("/api/index/1/0.json")->status, 404);
  std::ofstream(f.db / "movies/c1/t1.mp4", std::ios::trunc) << "garbage garbage garbage garbage";
  EXPECT_EQ(c.Get("/api/index/1/1.json")->status, 422);

  std::lock_guard lock(log_mutex);
  bool logged_range = false;
  for (const auto& line : log) logged_range |= line.find("GET /db/movies/c2/t1.mp4 206 bytes=") != std::string::npos;
  EXPECT_TRUE(logged_range) << "one log line per request, with the range";
}

// database.json is built once per opened database and query (issue 44, point 4: every request re-built
// the JSON of the whole manifest, 5.8-7.7 s each at 255 MB); a changed manifest is read again.
TEST(Server, DatabaseJsonIsBuiltOncePerManifest) {
  Fixture f;
  std::vector<std::string> log;
  std::mutex log_mutex;
  auto o = options(f);
  o.log = [&](const std::string& line) {
    std::lock_guard lock(log_mutex);
    log.push_back(line);
  };
  const auto builds = [&] {
    std::lock_guard lock(log_mutex);
    int n = 0;
    for (const auto& line : log) n += line.find("database.json built") != std::string::npos;
    return n;
  };
  Running r(o);
  httplib::Client c("127.0.0.1", r.server.port());
  std::string first;
  for (int i = 0; i < 3; ++i) {
    auto res = c.Get("/api/database.json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200);
    if (i == 0) first = res->body;
    EXPECT_EQ(res->body, first);
  }
  EXPECT_EQ(builds(), 1);
  ASSERT_EQ(c.Get("/api/database.json?cameras=inline")->status, 200);
  ASSERT_EQ(c.Get("/api/database.json?cameras=inline")->status, 200);
  EXPECT_EQ(builds(), 2);  // another query: its own entry
  // A new manifest (a checkpoint of a running simulation rewrites it): read and built again.
  const fs::path man = f.db / store::kManifestFileName;
  nlohmann::json m = nlohmann::json::parse(read_file(man));
  m["title"] = "renamed " + m.value("title", std::string());
  std::ofstream(man, std::ios::trunc) << m.dump(1);
  fs::last_write_time(man, fs::last_write_time(man) + std::chrono::seconds(2));
  auto res = c.Get("/api/database.json");
  ASSERT_TRUE(res);
  EXPECT_NE(res->body.find("renamed "), std::string::npos);
  EXPECT_EQ(builds(), 3);
}

// A packed database (issue 46): the index names the pack and the ranges of the stream in it, and the
// bytes come straight from the pack by Range requests; init + fragments is a movie with its stamps.
TEST(Server, PackedDatabaseIndexNamesPackRangesServedByteForByte) {
  Fixture f;  // for the player directory
  const fs::path db = f.tmp.path / "packed";
  testing::write_packed_database(db, 3, 2, 4);
  auto o = options(f);
  o.database = db;
  Running r(o);
  httplib::Client c("127.0.0.1", r.server.port());
  auto res = c.Get("/api/database.json");
  ASSERT_TRUE(res);
  EXPECT_EQ(nlohmann::json::parse(res->body)["layout"], "packed");
  EXPECT_EQ(nlohmann::json::parse(res->body)["frames"], 4);

  const store::Database reference = store::Database::open(db);
  for (int camera = 0; camera < 3; ++camera) {
    res = c.Get("/api/index/" + std::to_string(camera) + "/1.json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    const auto index = nlohmann::json::parse(res->body);
    ASSERT_EQ(index["files"].size(), 1u);
    const std::string pack = index["files"][0];
    EXPECT_EQ(pack, "db/packs/" + store::pack_file_name(0, 0));
    const store::PackedStream ps = reference.packed_stream(camera, 1);
    ASSERT_EQ(index["fragments"].size(), ps.pieces.size() - 1);
    EXPECT_EQ(index["init"], nlohmann::json::array({0, ps.pieces[0].offset, ps.pieces[0].size}));
    EXPECT_EQ(index["init_size"], ps.pieces[0].size);
    std::string movie;
    const auto get = [&](std::uint64_t offset, std::uint64_t size) {
      auto part = c.Get("/" + pack, {{"Range", "bytes=" + std::to_string(offset) + "-" + std::to_string(offset + size - 1)}});
      EXPECT_TRUE(part);
      EXPECT_EQ(part->status, 206);
      EXPECT_EQ(part->body, testing::read_range(ps.pieces[0].file, offset, size));
      return part->body;
    };
    movie += get(ps.pieces[0].offset, ps.pieces[0].size);
    for (std::size_t k = 0; k < ps.pieces.size() - 1; ++k) {
      const auto& fr = index["fragments"][k];
      const auto& piece = ps.pieces[k + 1];
      EXPECT_EQ(fr, nlohmann::json::array({piece.offset, piece.size, int(k), 1, 0}));
      // Other streams' fragments lie between this stream's: the player fetches them one run each.
      if (k > 0) {
        EXPECT_GT(piece.offset, ps.pieces[k].offset + ps.pieces[k].size);
      }
      movie += get(fr[0], fr[1]);
    }
    // What a browser assembles plays, with this stream's stamps.
    const fs::path cut = f.tmp.path / ("cut" + std::to_string(camera) + ".mp4");
    std::ofstream(cut, std::ios::binary) << movie;
    video::MovieReader reader(cut.string(), reference.frame_checks(camera, 1));
    ASSERT_EQ(reader.frame_count(), 4);
    EXPECT_TRUE(reader.check_frames().empty());
    EXPECT_EQ(read_frame_stamp(reader.read_rgba(3)), (FrameStamp{std::uint32_t(camera), 1, 3}));
  }
  // Asked again, the same index (from the cache).
  const auto again = c.Get("/api/index/2/1.json");
  ASSERT_TRUE(again);
  EXPECT_EQ(nlohmann::json::parse(again->body)["fragments"].size(), 4u);
  // Out of range: 404, as for a files database.
  EXPECT_EQ(c.Get("/api/index/3/0.json")->status, 404);
}

TEST(Server, NoPathOutsideTheDatabaseCanBeReached) {
  Fixture f;
  Running r(options(f));
  httplib::Client c("127.0.0.1", r.server.port());
  c.set_url_encode(false);  // send the paths exactly as written
  const char* attacks[] = {
      "/db/../secret.txt",
      "/db/movies/../../secret.txt",
      "/db/%2e%2e/secret.txt",
      "/db/%2E%2E/secret.txt",
      "/db/%2e%2e%2fsecret.txt",
      "/db/movies/c0/..%2f..%2f..%2fsecret.txt",
      "/db/.%2e/secret.txt",
      "/db//etc/passwd",
      "/db/%2fetc%2fpasswd",
      "/db/movies/outside/secret.txt",  // directory link out of the database
      "/db/movies/c0/secret.mp4",       // file link out of the database
      "/db/.panoptes.lock",
      "/../secret.txt",
      "/%2e%2e/secret.txt",
      "/..%2fsecret.txt",
      "/db/movies\\..\\..\\secret.txt",
      "/db/movies/c0/t0.mp4%00.txt",
  };
  for (const char* path : attacks) {
    auto res = c.Get(path);
    if (!res) continue;  // the library refused to send or parse it: also fine
    EXPECT_NE(res->status, 200) << path;
    EXPECT_NE(res->status, 206) << path;
    EXPECT_EQ(res->body.find("TOP-SECRET"), std::string::npos) << path;
  }
  // The same server still serves what it should.
  EXPECT_EQ(c.Get("/db/movies/c0/t0.mp4")->status, 200);
}

TEST(Server, TokenIsRequiredWhenGiven) {
  Fixture f;
  Running r(options(f, "s3cret-t0ken"));
  httplib::Client c("127.0.0.1", r.server.port());
  EXPECT_EQ(c.Get("/api/database.json")->status, 401);
  EXPECT_EQ(c.Get("/db/movies/c0/t0.mp4")->status, 401);
  EXPECT_EQ(c.Get("/api/database.json?token=wrong-t0ken!")->status, 401);
  EXPECT_EQ(c.Get("/api/database.json?token=s3cret-t0ke")->status, 401);
  EXPECT_EQ(c.Get("/api/database.json", {{"Authorization", "Bearer wrong"}})->status, 401);
  EXPECT_EQ(c.Get("/api/database.json", {{"Cookie", "panoptes_token=wrong"}})->status, 401);

  auto res = c.Get("/?token=s3cret-t0ken");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_NE(res->get_header_value("Set-Cookie").find("panoptes_token=s3cret-t0ken"), std::string::npos);
  EXPECT_EQ(c.Get("/api/database.json", {{"Authorization", "Bearer s3cret-t0ken"}})->status, 200);
  EXPECT_EQ(c.Get("/db/movies/c0/t0.mp4", {{"Cookie", "x=1; panoptes_token=s3cret-t0ken"}})->status, 200);
}

TEST(Server, ManyConcurrentClientsGetTheirRanges) {
  Fixture f;
  Running r(options(f));
  const std::string movie = read_file(f.db / "movies/c1/t1.mp4");
  std::atomic<int> good{0}, bad{0};
  std::vector<std::thread> clients;
  for (int k = 0; k < 16; ++k) {
    clients.emplace_back([&, k] {
      httplib::Client c("127.0.0.1", r.server.port());
      for (int i = 0; i < 10; ++i) {
        const std::size_t a = (k * 131 + i * 17) % (movie.size() - 64), b = a + 63;
        auto res = c.Get("/db/movies/c1/t1.mp4", {{"Range", "bytes=" + std::to_string(a) + "-" + std::to_string(b)}});
        (res && res->status == 206 && res->body == movie.substr(a, 64) ? good : bad)++;
      }
    });
  }
  for (auto& t : clients) t.join();
  EXPECT_EQ(good, 160);
  EXPECT_EQ(bad, 0);
}

TEST(Server, RefusesBadDirectoriesAndBusyPorts) {
  Fixture f;
  auto o = options(f);
  o.database = f.tmp.path / "nope";
  EXPECT_THROW(Server{o}, Error);
  o = options(f);
  o.player_dir = f.db;  // no index.html
  EXPECT_THROW(Server{o}, FileError);
  Running r(options(f));
  o = options(f);
  o.port = r.server.port();
  EXPECT_THROW(Server{o}, Error);
}

}  // namespace
}  // namespace panoptes::web
