// A database from a stranger: links out of the directory, FIFOs, devices, oversize files, deeply
// nested or overflowing JSON, absurd sizes. Each case of issue #15 (campaign "path escapes",
// "mutated panoptes.json", "mutated camera tables") is one test: nothing outside the database is
// written or read, nothing blocks, nothing crashes, and the message names the file and the value.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "store/bounded_json.hpp"
#include "store/camera_table.hpp"
#include "store/database.hpp"
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

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void spit(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

// A complete one-frame database of 2 cameras x 1 task.
void make_database(const fs::path& dir) {
  DatabaseWriter w = DatabaseWriter::create(dir, sample_manifest(2, 1, 32, 32));
  Image img(32, 32, 3);
  for (int c = 0; c < 2; ++c) w.append(c, 0, img);
  w.finalize();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A self-contained manifest text (inline cameras) where the value of `key` in `object` is `value`.
std::string manifest_with(const std::string& where, const std::string& value) {
  nlohmann::json j = to_json(sample_manifest(2, 1));
  if (where == "rig") j["rig"]["parameters"] = "@@HERE@@";
  else j["tasks"][0]["parameters"] = "@@HERE@@";
  std::string text = j.dump();
  const auto at = text.find("\"@@HERE@@\"");
  return text.replace(at, 10, value);
}

}  // namespace

TEST(HostileDatabase, LockSymlinkOutsideIsNeverWrittenThrough) {
  TempDir dir, outside("outside");
  const fs::path victim = outside / "precious.txt";
  spit(victim, "precious data\n");
  fs::create_directories(dir.path);
  fs::create_symlink(victim, dir / kLockFileName);
  EXPECT_CONTAINS(error_of([&] { DatabaseWriter::create(dir.path, sample_manifest(2, 1, 32, 32)); }), "symbolic link");
  EXPECT_EQ(slurp(victim), "precious data\n");
  // Also with --overwrite of an existing database whose lock was replaced by a link.
  fs::remove(dir / kLockFileName);
  make_database(dir.path);
  fs::create_symlink(victim, dir / kLockFileName);
  WriterOptions o;
  o.overwrite = true;
  EXPECT_CONTAINS(error_of([&] { DatabaseWriter::create(dir.path, sample_manifest(2, 1, 32, 32), o); }), "symbolic link");
  EXPECT_EQ(slurp(victim), "precious data\n");
}

TEST(HostileDatabase, ManifestSymlinkIsNotRead) {
  TempDir dir, outside("outside");
  make_database(dir.path);
  const fs::path secret = outside / "passwd";
  spit(secret, "root:x:0:0:SECRET:/root:/bin/bash\n");
  fs::remove(dir / kManifestFileName);
  fs::create_symlink(secret, dir / kManifestFileName);
  const std::string e = error_of([&] { Database::open(dir.path); });
  EXPECT_CONTAINS(e, "symbolic link");
  EXPECT_EQ(e.find("SECRET"), std::string::npos) << e;
  // A link to /dev/zero: refused at once, nothing read.
  fs::remove(dir / kManifestFileName);
  fs::create_symlink("/dev/zero", dir / kManifestFileName);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "symbolic link");
  EXPECT_LT(seconds_since(t0), 1.0);
}

TEST(HostileDatabase, FifosDoNotBlockReaders) {
  TempDir dir;
  make_database(dir.path);
  const auto t0 = std::chrono::steady_clock::now();
  // The lock as a FIFO: no live writer, not a hang.
  ASSERT_EQ(::mkfifo((dir / kLockFileName).c_str(), 0644), 0);
  EXPECT_FALSE(writer_is_alive(dir.path));
  EXPECT_NO_THROW(Database::open(dir.path));
  // The camera table as a FIFO.
  const std::string table = referenced_camera_table(dir / kManifestFileName);
  ASSERT_FALSE(table.empty());
  fs::remove(dir / table);
  ASSERT_EQ(::mkfifo((dir / table).c_str(), 0644), 0);
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "FIFO");
  // The manifest as a FIFO.
  fs::remove(dir / kManifestFileName);
  ASSERT_EQ(::mkfifo((dir / kManifestFileName).c_str(), 0644), 0);
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "FIFO");
  // A movie as a FIFO.
  TempDir dir2;
  make_database(dir2.path);
  fs::remove(dir2 / "movies/c0/t0.mp4");
  ASSERT_EQ(::mkfifo((dir2 / "movies/c0/t0.mp4").c_str(), 0644), 0);
  const Database db = Database::open(dir2.path);
  EXPECT_CONTAINS(error_of([&] { db.stream(0, 0); }), "not a regular file");
  EXPECT_LT(seconds_since(t0), 5.0);
}

TEST(HostileDatabase, OversizeManifestIsRefusedWithoutReading) {
  TempDir dir;
  make_database(dir.path);
  // Sparse: takes no disk space, but claims more than the limit.
  const int fd = ::open((dir / kManifestFileName).c_str(), O_WRONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, off_t(kMaxManifestBytes) + 1), 0);
  ::close(fd);
  const std::string e = error_of([&] { Database::open(dir.path); });
  EXPECT_CONTAINS(e, "more than the limit of " + std::to_string(kMaxManifestBytes));
}

TEST(HostileDatabase, WriterRefusesAPlantedMoviesSymlink) {
  TempDir dir, outside("outside");
  fs::create_directories(dir.path);
  fs::create_symlink(outside.path, dir / "movies");
  DatabaseWriter w = DatabaseWriter::create(dir.path, sample_manifest(2, 1, 32, 32));
  Image img(32, 32, 3);
  EXPECT_CONTAINS(error_of([&] { w.append(0, 0, img); }), "symbolic link");
  EXPECT_TRUE(fs::is_empty(outside.path)) << "a movie was written through the link";
  // A planted link at the movie itself.
  TempDir dir2, outside2("outside");
  const fs::path victim = outside2 / "victim";
  spit(victim, "keep me");
  fs::create_directories(dir2 / "movies/c0");
  fs::create_symlink(victim, dir2 / "movies/c0/t0.mp4");
  DatabaseWriter w2 = DatabaseWriter::create(dir2.path, sample_manifest(2, 1, 32, 32));
  EXPECT_CONTAINS(error_of([&] { w2.append(0, 0, img); }), "symbolic link");
  EXPECT_EQ(slurp(victim), "keep me");
}

TEST(HostileDatabase, DeeplyNestedParametersAreRefusedNotACrash) {
  // These three manifests crashed `info` and `play` (stack overflow copying the DOM).
  for (const std::string where : {"task", "rig"}) {
    for (const char* open_close : {"{\"a\":", "["}) {
      const int depth = 200000;
      std::string deep;
      deep.reserve(std::size_t(depth) * 5 + 10);
      for (int i = 0; i < depth; ++i) deep += open_close;
      deep += "1";
      for (int i = 0; i < depth; ++i) deep += open_close[0] == '{' ? '}' : ']';
      const std::string e = error_of([&] { parse_bounded_json(manifest_with(where, deep), "db/panoptes.json"); });
      EXPECT_CONTAINS(e, "db/panoptes.json");
      EXPECT_CONTAINS(e, "nested deeper than 64");
      EXPECT_CONTAINS(e, where == "rig" ? "malformed JSON at rig.parameters" : "malformed JSON at tasks[0].parameters");
    }
  }
  // Through the whole reader.
  TempDir dir;
  fs::create_directories(dir.path);
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "{\"a\":";
  deep += "1";
  deep += std::string(100000, '}');
  spit(dir / kManifestFileName, manifest_with("rig", deep));
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "nested deeper");
  // A modest depth is fine.
  spit(dir / kManifestFileName, manifest_with("rig", "{\"a\":{\"b\":{\"c\":[1,2,{\"d\":3}]}}}"));
  EXPECT_NO_THROW(Database::open(dir.path));
}

TEST(HostileDatabase, JsonErrorsNameTheFileAndKeyPath) {
  const std::string e = error_of([&] { parse_bounded_json(manifest_with("task", "{\"isovalue\": 1e999}"), "db/panoptes.json"); });
  EXPECT_CONTAINS(e, "db/panoptes.json: malformed JSON at tasks[0].parameters.isovalue");
  EXPECT_CONTAINS(e, "1e999");
  EXPECT_EQ(e.find("[json.exception"), std::string::npos) << e;
  const std::string e2 = error_of([&] { parse_bounded_json("{\"times\": [0, 1, 2, -1e400]}", "m.json"); });
  EXPECT_CONTAINS(e2, "m.json: malformed JSON at times[3]");
  const std::string e3 = error_of([&] { parse_bounded_json("{\"a\": [1, 2,", "m.json"); });
  EXPECT_CONTAINS(e3, "m.json: malformed JSON at a[2]");
  JsonLimits small;
  small.max_string = 8;
  small.max_elements = 3;
  EXPECT_CONTAINS(error_of([&] { parse_bounded_json("{\"k\": \"123456789\"}", "m.json", small); }), "longer than the limit");
  EXPECT_CONTAINS(error_of([&] { parse_bounded_json("{\"k\": [1,2,3,4]}", "m.json", small); }), "more than 3 elements");
}

TEST(HostileDatabase, AbsurdSizesAreRefusedQuickly) {
  TempDir dir;
  make_database(dir.path);
  nlohmann::json j = parse_bounded_json(slurp(dir / kManifestFileName), "m");
  // An image of 20000x20000: a reader would allocate placeholders and frames of 1.6 GB.
  nlohmann::json big = j;
  big["image"]["width"] = 20000;
  big["image"]["height"] = 20000;
  spit(dir / kManifestFileName, big.dump());
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "image size 20000x20000 is larger than H.264 allows");
  // A camera table of 2*10^7 (shared) cameras.
  nlohmann::json many = j;
  many["camera_table"]["cameras"] = 20000000;
  spit(dir / kManifestFileName, many.dump());
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "camera_table.cameras: 20000000 is out of range");
  EXPECT_LT(seconds_since(t0), 1.0);
  // A table file larger than the manifest records is not read in.
  spit(dir / kManifestFileName, j.dump());
  const fs::path table = dir / j["camera_table"]["file"].get<std::string>();
  fs::resize_file(table, fs::file_size(table) + (std::uint64_t(1) << 30));
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "more than the limit");
}

TEST(HostileDatabase, CameraTableMessagesSayWhichValuesDisagree) {
  const Manifest m = sample_manifest(5, 1);
  const std::string bytes = encode_camera_table(m);
  CameraTableRef ref;
  ref.bytes = bytes.size();
  ref.cameras = 5;
  ref.navigation = true;
  std::uint32_t crc = 0;
  std::memcpy(&crc, bytes.data() + 12, 4);
  ref.crc32 = crc;
  Manifest out;
  // Contents changed, header checksum not recomputed: contents and header disagree.
  std::string damaged = bytes;
  damaged[bytes.size() - 3] ^= 0x40;
  const std::string e1 = error_of([&] { decode_camera_table(damaged, ref, "t.bin", out); });
  EXPECT_CONTAINS(e1, "the CRC-32 of its contents is ");
  EXPECT_CONTAINS(e1, "its header records " + camera_table_file_name(crc).substr(8, 8));
  // Table intact, manifest records another checksum: the table and the manifest disagree.
  CameraTableRef other = ref;
  other.crc32 = crc ^ 1u;
  const std::string e2 = error_of([&] { decode_camera_table(bytes, other, "t.bin", out); });
  EXPECT_CONTAINS(e2, "(its contents and header agree) differs from the " + camera_table_file_name(crc ^ 1u).substr(8, 8) +
                          " the manifest records");
  // Never one value named twice as if it disagreed with itself.
  const std::string hex = camera_table_file_name(crc).substr(8, 8);
  EXPECT_EQ(e2.find(hex + ", header records " + hex), std::string::npos) << e2;
}
