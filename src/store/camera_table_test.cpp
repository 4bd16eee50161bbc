// The binary camera table (schema 2): round trip, the version-1 compatibility path, checkpoint
// behaviour, and a clear error naming the file and the value for every kind of damage.
#include "store/camera_table.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <iterator>

#include "core/error.hpp"
#include "store/database.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
using namespace panoptes::store;
using panoptes::store::testing::sample_manifest;
using panoptes::store::testing::TempDir;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

using panoptes::store::testing::error_of;

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write_bytes(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary | std::ios::trunc) << s; }

// Writes a database manifest (no movies) and returns the path of its camera table.
fs::path write_sample(const TempDir& dir, const Manifest& m) {
  write_manifest_atomic(dir / kManifestFileName, m);
  return dir / referenced_camera_table(dir / kManifestFileName);
}

// Rewrites a little-endian u32 at `at` and fixes the header checksum, so that only the value is wrong.
void patch_u32(std::string& bytes, std::size_t at, std::uint32_t v, bool fix_crc = true) {
  for (int k = 0; k < 4; ++k) bytes[at + std::size_t(k)] = char((v >> (8 * k)) & 0xFF);
  if (fix_crc) {
    const std::uint32_t crc = crc32(bytes.data() + 16, bytes.size() - 16);
    for (int k = 0; k < 4; ++k) bytes[12 + std::size_t(k)] = char((crc >> (8 * k)) & 0xFF);
  }
}

// Offset of the data of the column called `name` (from its descriptor).
std::size_t column_offset(const std::string& bytes, const std::string& name) {
  const std::uint32_t n = std::uint8_t(bytes[32]) | std::uint8_t(bytes[33]) << 8;
  for (std::uint32_t c = 0; c < n; ++c) {
    const std::size_t d = 40 + 56 * std::size_t(c);
    if (std::string(bytes.data() + d) == name) {
      std::uint64_t off = 0;
      for (int k = 7; k >= 0; --k) off = off << 8 | std::uint8_t(bytes[d + 40 + std::size_t(k)]);
      return std::size_t(off);
    }
  }
  ADD_FAILURE() << "no column " << name;
  return 0;
}

}  // namespace

TEST(CameraTable, Crc32MatchesTheStandardCheckValue) {
  EXPECT_EQ(crc32("123456789", 9), 0xCBF43926u);
  EXPECT_EQ(crc32("", 0), 0u);
  // Incremental = one shot, across the 8-byte blocks.
  const std::string s = "The quick brown fox jumps over the lazy dog";
  EXPECT_EQ(crc32(s.data() + 13, s.size() - 13, crc32(s.data(), 13)), crc32(s.data(), s.size()));
  EXPECT_EQ(crc32(s.data(), s.size()), 0x414FA339u);
}

TEST(CameraTable, RoundTripKeepsEveryCameraField) {
  Manifest m = sample_manifest(9, 2);
  m.cameras[2].labels.extra = {{"note", "pole"}, {"radius", "2.5"}};
  m.cameras[8].labels.extra = {{"x", ""}};
  m.cameras[3].labels.shell = 1;
  m.cameras[4].labels.patch = "yang";
  m.cameras[5].labels.patch = "";
  m.cameras[6].look_at = {0.5, -1, 2};
  m.cameras[7].fov_y_deg = 12.5;
  m.graph.neighbours[1].in = 3;
  m.graph.neighbours[3].out = 1;
  TempDir dir;
  const fs::path table = write_sample(dir, m);
  EXPECT_EQ(table.filename().string().rfind("cameras.", 0), 0u);
  const Manifest back = read_manifest(dir / kManifestFileName);
  EXPECT_EQ(back.cameras, m.cameras);
  EXPECT_EQ(back.graph, m.graph);
  EXPECT_EQ(to_json(back), to_json(m));
  // The manifest itself holds no camera rows.
  const json j = json::parse(read_bytes(dir / kManifestFileName));
  EXPECT_EQ(j.at("schema_version"), 2);
  EXPECT_FALSE(j.contains("cameras"));
  EXPECT_FALSE(j.at("navigation").contains("neighbours"));
  EXPECT_EQ(j.at("camera_table").at("cameras"), 9);
  EXPECT_EQ(j.at("camera_table").at("bytes"), fs::file_size(table));

  // Without a graph, and with no cameras at all.
  m.graph.neighbours.clear();
  write_manifest_atomic(dir / kManifestFileName, m);
  EXPECT_TRUE(read_manifest(dir / kManifestFileName).graph.empty());
  Manifest none = sample_manifest(0, 1);
  write_manifest_atomic(dir / kManifestFileName, none);
  EXPECT_EQ(read_manifest(dir / kManifestFileName).camera_count(), 0);
  // Old tables are removed when the manifest moves on to another one.
  int tables = 0;
  for (const auto& e : fs::directory_iterator(dir.path)) tables += e.path().extension() == ".bin";
  EXPECT_EQ(tables, 1);
}

TEST(CameraTable, SharedColumnsAreStoredOnce) {
  // 2000 cameras share look_at, up, fov, shell and patch: per camera only position, lat, lon and the
  // graph remain (24 + 8 + 8 + 24 = 64 bytes), plus a fixed header and column table.
  const Manifest m = sample_manifest(2000, 1);
  const std::size_t bytes = encode_camera_table(m).size();
  EXPECT_GE(bytes, 2000u * 64u);
  EXPECT_LT(bytes, 2000u * 64u + 2048u);
}

TEST(CameraTable, SchemaVersion1ManifestsAreStillRead) {
  TempDir dir;
  Manifest m = sample_manifest(5, 2);
  json j = to_json(m);
  j["schema_version"] = 1;  // version 1: cameras and graph inline
  std::ofstream(dir / kManifestFileName) << j.dump();
  const Manifest back = read_manifest(dir / kManifestFileName);
  EXPECT_EQ(back.schema_version, 1);
  EXPECT_EQ(back.cameras, m.cameras);
  EXPECT_EQ(back.graph, m.graph);
  // Written back, it becomes version 2 with a camera table.
  write_manifest_atomic(dir / kManifestFileName, back);
  const json again = json::parse(read_bytes(dir / kManifestFileName));
  EXPECT_EQ(again.at("schema_version"), 2);
  EXPECT_TRUE(again.contains("camera_table"));
  EXPECT_EQ(read_manifest(dir / kManifestFileName).cameras, m.cameras);
  // A version-1 manifest cannot refer to a table.
  j["camera_table"] = {{"file", "cameras.0.bin"}, {"bytes", 1}, {"crc32", 0}, {"cameras", 5}};
  EXPECT_CONTAINS(error_of([&] { manifest_from_json(j, "f", dir.path); }), "camera_table: is not part of schema_version 1");
  // Schema 2: inline or table, not both.
  j["schema_version"] = 2;
  EXPECT_CONTAINS(error_of([&] { manifest_from_json(j, "f", dir.path); }), "one or the other");
}

TEST(CameraTable, DamagedTablesAreRefusedNamingFileFieldAndValue) {
  TempDir dir;
  const Manifest m = sample_manifest(6, 1);
  const fs::path table = write_sample(dir, m);
  const std::string good = read_bytes(table);
  const std::string name = table.string();
  const auto open_error = [&](const std::string& bytes) {
    write_bytes(table, bytes);
    return error_of([&] { Database::open(dir.path); });
  };

  // Truncated: shorter than the manifest and the header record.
  std::string e = open_error(good.substr(0, good.size() - 10));
  EXPECT_CONTAINS(e, name);
  EXPECT_CONTAINS(e, "truncated");
  EXPECT_CONTAINS(e, std::to_string(good.size() - 10));
  EXPECT_CONTAINS(open_error(good.substr(0, 20)), "shorter than its 40-byte header");
  EXPECT_CONTAINS(open_error(""), "wrong magic");

  // Wrong magic.
  std::string bad = good;
  bad[0] = 'X';
  e = open_error(bad);
  EXPECT_CONTAINS(e, name);
  EXPECT_CONTAINS(e, "not a Panoptes camera table");

  // Newer layout version.
  bad = good;
  patch_u32(bad, 8, 7);
  EXPECT_CONTAINS(open_error(bad), "camera table format version 7 is not supported");

  // One flipped bit in the payload: checksum mismatch, naming both values.
  bad = good;
  bad[bad.size() - 3] ^= 0x10;
  e = open_error(bad);
  EXPECT_CONTAINS(e, name);
  EXPECT_CONTAINS(e, "checksum mismatch");
  char hex[16];
  std::snprintf(hex, sizeof hex, "%08x", crc32(bad.data() + 16, bad.size() - 16));
  EXPECT_CONTAINS(e, hex);

  // A consistent table that is not the one the manifest recorded (checksum differs).
  bad = good;
  patch_u32(bad, 36, 1);  // reserved field: same size, valid header checksum, other contents
  EXPECT_CONTAINS(open_error(bad), "manifest records");

  // Patches one u32 of a column and fixes both checksums, so that only the value is wrong.
  const auto open_patched_at = [&](std::size_t at, std::uint32_t v) {
    std::string b = good;
    patch_u32(b, at, v);
    write_bytes(table, b);
    json jj = json::parse(read_bytes(dir / kManifestFileName));
    jj["camera_table"]["crc32"] = crc32(b.data() + 16, b.size() - 16);
    std::ofstream(dir / kManifestFileName, std::ios::trunc) << jj.dump();
    return error_of([&] { Database::open(dir.path); });
  };
  const auto open_patched = [&](const std::string& column, std::size_t at, std::uint32_t v) {
    return open_patched_at(column_offset(good, column) + at, v);
  };
  // Neighbour out of range.
  e = open_patched("neighbours", 4 * 7, 6);  // camera 1, "right" = 6 of 6 cameras
  EXPECT_CONTAINS(e, name);
  EXPECT_CONTAINS(e, "navigation graph entry 1 names camera 6 (valid: -1 or 0..5)");
  EXPECT_CONTAINS(open_patched("neighbours", 4 * 7, std::uint32_t(-2)), "names camera -2");

  // Count mismatch between the table and the manifest.
  e = open_patched_at(24, 5);
  EXPECT_CONTAINS(e, name);
  EXPECT_CONTAINS(e, "holds 5 cameras, the manifest records 6");

  // Bad values inside the table: fov out of range, patch index out of range, NaN.
  EXPECT_CONTAINS(open_patched("fov_y_deg", 4, 0x40700000u), "fov_y_deg 256.000000 is not in (0, 180)");  // 256.0
  EXPECT_CONTAINS(open_patched("patch", 0, 9), "camera 0 names patch 9 of 1");
  EXPECT_CONTAINS(open_patched("position", 4, 0x7FF80000u), "non-finite");  // NaN

  // Missing table, and a table file name that would leave the directory.
  write_manifest_atomic(dir / kManifestFileName, m);
  fs::remove(dir / referenced_camera_table(dir / kManifestFileName));
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "camera table missing");
  json j = json::parse(read_bytes(dir / kManifestFileName));
  j["camera_table"]["file"] = "../cameras.bin";
  std::ofstream(dir / kManifestFileName, std::ios::trunc) << j.dump();
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "camera_table.file");
}

TEST(CameraTable, LinkOutOfTheDatabaseIsRefused) {
  TempDir dir, outside;
  const Manifest m = sample_manifest(3, 1);
  const fs::path table = write_sample(dir, m);
  fs::rename(table, outside / table.filename().string());
  fs::create_symlink(outside / table.filename().string(), table);
  EXPECT_CONTAINS(error_of([&] { Database::open(dir.path); }), "symbolic link");
}

TEST(CameraTable, CheckpointsRewriteOnlyTheManifest) {
  TempDir dir;
  auto writer = DatabaseWriter::create(dir / "db", sample_manifest(50, 1), true);
  const fs::path table = dir / "db" / referenced_camera_table(dir / "db" / kManifestFileName);
  const auto before = fs::last_write_time(table);
  const auto inode = [](const fs::path& p) {
    struct stat st {};
    ::stat(p.c_str(), &st);
    return st.st_ino;
  };
  const auto ino = inode(table);
  writer.set_time(0, 0.5);
  writer.checkpoint(0);
  writer.finalize(0);
  EXPECT_EQ(inode(table), ino);  // not replaced
  EXPECT_EQ(fs::last_write_time(table), before);
  const Database db = Database::open(dir / "db");
  EXPECT_EQ(db.status(), Status::complete);
  EXPECT_EQ(db.manifest().cameras, sample_manifest(50, 1).cameras);
  // Overwriting with other cameras replaces the table and removes the old one.
  DatabaseWriter::create(dir / "db", sample_manifest(7, 1), true).finalize();
  EXPECT_FALSE(fs::exists(table));
  EXPECT_EQ(Database::open(dir / "db").camera_count(), 7);
}
