// Cinema databases as hostile input (issue #31 rows 4, 9, 10, 11): every reproducer of the campaign
// is refused in one line, quickly, without a crash or unbounded memory.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <fstream>

#include "cinema/cinema_database.hpp"
#include "cinema/export.hpp"
#include "cinema/image_file.hpp"
#include "cinema/import.hpp"
#include "core/error.hpp"
#include "core/png.hpp"
#include "store/database.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
namespace fs = std::filesystem;
using store::testing::error_of;
using store::testing::TempDir;

namespace {

using store::testing::write_file;

void small_png(const fs::path& p) {
  fs::create_directories(p.parent_path());
  Image img(8, 6, 3);
  write_png(p.string(), img);
}

double seconds_of(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

// Row 4: info.json nested 10^5 deep overflowed the stack of the recursive JSON copy.
TEST(HostileCinema, DeeplyNestedInfoJsonIsRefused) {
  TempDir tmp("hostile_cinema");
  write_file(tmp / "a.cdb/info.json", std::string(100000, '[') + std::string(100000, ']'));
  const std::string e = error_of([&] { cinema::plan_import(tmp / "a.cdb"); });
  EXPECT_NE(e.find("nested deeper than 32 levels"), std::string::npos) << e;
}

// Row 9: data.csv / info.json as a FIFO blocked forever, as /dev/zero ended in bad_alloc.
TEST(HostileCinema, FifoAndDeviceTablesAreRefused) {
  TempDir tmp("hostile_cinema");
  fs::create_directories(tmp / "f.cdb");
  ASSERT_EQ(::mkfifo((tmp / "f.cdb/data.csv").c_str(), 0644), 0);
  std::string e = error_of([&] { cinema::plan_import(tmp / "f.cdb"); });
  EXPECT_NE(e.find("FIFO"), std::string::npos) << e;
  fs::create_directories(tmp / "d.cdb");
  fs::create_symlink("/dev/zero", tmp / "d.cdb/info.json");
  e = error_of([&] { cinema::plan_import(tmp / "d.cdb"); });
  EXPECT_NE(e.find("symbolic link"), std::string::npos) << e;
}

// Row 9: memory grew as rows^3 (one slot per camera x task x time): 3,000 rows of distinct cameras,
// tasks and times asked for 2.7e10 slots. Now linear: the missing view is found at once.
TEST(HostileCinema, TableMemoryIsLinearInRows) {
  TempDir tmp("hostile_cinema");
  small_png(tmp / "c.cdb/a.png");
  std::string csv = "time,phi,theta,level,FILE\n";
  for (int r = 0; r < 3000; ++r) csv += std::to_string(r) + "," + std::to_string(r % 360) + ".5,0," + std::to_string(r) + ",a.png\n";
  write_file(tmp / "c.cdb/data.csv", csv);
  cinema::ImportOptions o;
  o.angles = "elevation";
  std::string e;
  const double s = seconds_of([&] { e = error_of([&] { cinema::plan_import(tmp / "c.cdb", o); }); });
  EXPECT_NE(e.find("no image for camera"), std::string::npos) << e;
  EXPECT_LT(s, 5.0);
}

// Row 9: CPU was quadratic in the columns (10^5 columns took > 20 s). The time bound holds for an
// optimized build; under the sanitizers (-O0, ASan: ~20x slower) the test checks memory safety on
// fewer columns and no time.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kColumns = 20000;
constexpr double kColumnSeconds = 1e9;
#else
constexpr int kColumns = 100000;
constexpr double kColumnSeconds = 10.0;
#endif
TEST(HostileCinema, HundredThousandColumnsAreFast) {
  TempDir tmp("hostile_cinema");
  small_png(tmp / "w.cdb/a.png");
  std::string header, row;
  for (int c = 0; c < kColumns; ++c) header += "p" + std::to_string(c) + ",", row += std::to_string(c) + ",";
  write_file(tmp / "w.cdb/data.csv", header + "FILE\n" + row + "a.png\n");
  cinema::ImportPlan plan;
  const double s = seconds_of([&] { plan = cinema::plan_import(tmp / "w.cdb"); });
  EXPECT_EQ(plan.manifest.task_count(), 1);
  EXPECT_EQ(plan.manifest.tasks[0].name, "task 0");  // too many columns to name it by them
  EXPECT_LT(s, kColumnSeconds);
}

// Row 9: a 2 MiB field became a task name the project's own `info` then refused.
TEST(HostileCinema, OverlongFieldsAreRefused) {
  TempDir tmp("hostile_cinema");
  small_png(tmp / "l.cdb/a.png");
  write_file(tmp / "l.cdb/data.csv", "task,FILE\n" + std::string(2 << 20, 'x') + ",a.png\n");
  const std::string e = error_of([&] { cinema::plan_import(tmp / "l.cdb"); });
  EXPECT_NE(e.find("line 2: value of column task \"xxxx"), std::string::npos) << e.substr(0, 300);
  EXPECT_NE(e.find("is longer than 4096 bytes; refused"), std::string::npos) << e.substr(0, 300);
  EXPECT_LT(e.size(), 400u);  // the value is not echoed whole
}

// Row 9: a 585-byte Spec A file expanded to 3.2 GB of rows: the parameter product is refused when it
// exceeds the files the database holds.
TEST(HostileCinema, SpecAProductIsBoundedByTheFilesPresent) {
  TempDir tmp("hostile_cinema");
  std::string params;
  for (int p = 0; p < 8; ++p)
    params += std::string(p ? "," : "") + "\"p" + std::to_string(p) + "\": {\"values\": [0,1,2,3,4,5,6,7,8,9]}";
  write_file(tmp / "s.cdb/info.json", "{\"name_pattern\": \"{p0}.png\", \"arguments\": {" + params + "}}");
  std::string e;
  const double s = seconds_of([&] { e = error_of([&] { cinema::plan_import(tmp / "s.cdb"); }); });
  EXPECT_NE(e.find("combinations, more than the database has files"), std::string::npos) << e;
  EXPECT_LT(s, 2.0);
}

// Row 10: Debian's stb_image lacks the DHT "n > 256" check; libjpeg-turbo refuses the table.
TEST(HostileCinema, CraftedJpegHuffmanTableIsRefused) {
  std::string jpeg = "\xFF\xD8";                               // SOI
  jpeg += std::string("\xFF\xC4\x00\x13\x00", 5);              // DHT, length 19, class 0 id 0
  jpeg += std::string(16, '\xFF');                             // 16 code counts of 255: 4080 symbols > 256
  jpeg += std::string(4096, '\x41');
  jpeg += "\xFF\xD9";
  const std::string e = error_of([&] {
    cinema::decode_image_bytes(reinterpret_cast<const std::uint8_t*>(jpeg.data()), jpeg.size(), "crafted.jpg");
  });
  EXPECT_NE(e.find("crafted.jpg: not a readable JPEG image"), std::string::npos) << e;
}

// Row 11: export-cinema of a manifest listing 10^4 tasks whose movies do not exist created 40,006
// directories before failing and left them; now it checks the movies first and stages its output.
TEST(HostileCinema, FailedExportLeavesNothingBehind) {
  TempDir tmp("hostile_cinema");
  store::SyntheticOptions so;
  so.cameras = 2;
  so.tasks = 3;
  so.frames = 1;
  so.width = 48;
  so.height = 32;
  store::write_synthetic_database(tmp / "db", so);
  const auto db = store::Database::open(tmp / "db");
  fs::remove(db.stream_path(1, 2));
  const std::string e = error_of([&] { cinema::export_cinema(tmp / "db", tmp / "out.cdb"); });
  EXPECT_NE(e.find("is missing or not a file; nothing exported"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(tmp / "out.cdb"));
  for (const auto& entry : fs::directory_iterator(tmp.path))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
  // A movie that exists but cannot be decoded fails mid-export: the staged tree is removed.
  std::ofstream(db.stream_path(1, 2)) << "not a movie";
  EXPECT_FALSE(error_of([&] { cinema::export_cinema(tmp / "db", tmp / "out.cdb"); }).empty());
  EXPECT_FALSE(fs::exists(tmp / "out.cdb"));
  for (const auto& entry : fs::directory_iterator(tmp.path))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}
