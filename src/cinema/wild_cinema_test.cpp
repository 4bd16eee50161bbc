// Cinema databases as found in public repositories (issue 44, point 5), rebuilt as tiny synthetic
// tables: a timestep column, per-image measure columns, .npz layers, a second image column, a
// cinema_python layout with ParaView's image column name, ParaView's Static camera mode and older
// Ascent's latitude-style theta. Each imports as its producer meant it, or is refused naming the real
// reason and the option that settles it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "cinema/csv.hpp"
#include "cinema/import.hpp"
#include "core/error.hpp"
#include "core/png.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
namespace fs = std::filesystem;
using store::testing::error_of;
using store::testing::TempDir;

namespace {

using store::testing::write_file;

// A tiny picture that differs with `seed`.
void png(const fs::path& p, int seed) {
  fs::create_directories(p.parent_path());
  Image img(16, 12, 3);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x) {
      std::uint8_t* q = img.at(x, y);
      q[0] = std::uint8_t(10 * x + seed * 37), q[1] = std::uint8_t(12 * y + seed * 11), q[2] = std::uint8_t(seed * 53);
    }
  write_png(p.string(), img);
}

bool has_warning(const std::vector<std::string>& warnings, std::initializer_list<const char*> parts) {
  for (const auto& w : warnings) {
    bool all = w.find('\n') == std::string::npos;
    for (const char* p : parts) all = all && w.find(p) != std::string::npos;
    if (all) return true;
  }
  return false;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

cinema::ImportOptions angles(const std::string& a) {
  cinema::ImportOptions o;
  o.angles = a;
  return o;
}

const store::CameraEntry* camera_at(const store::Manifest& m, const std::string& phi, const std::string& theta) {
  for (const auto& c : m.cameras)
    if (c.labels.extra.count("cinema_phi") && std::stod(c.labels.extra.at("cinema_phi")) == std::stod(phi) &&
        std::stod(c.labels.extra.at("cinema_theta")) == std::stod(theta))
      return &c;
  return nullptr;
}

}  // namespace

// A `timestep` column is the time axis, as `time` is (it was made a task per time step).
TEST(WildCinema, TimestepColumnGivesTheFrames) {
  TempDir tmp("wild_cinema");
  const fs::path cdb = tmp / "t.cdb";
  std::string csv = "timestep,phi,theta,FILE\n";
  int n = 0;
  for (int step : {0, 5})
    for (int phi : {0, 90}) {
      const std::string f = "img/" + std::to_string(step) + "_" + std::to_string(phi) + ".png";
      png(cdb / f, n++);
      csv += std::to_string(step) + "," + std::to_string(phi) + ",0," + f + "\n";
    }
  write_file(cdb / "data.csv", csv);
  const auto plan = cinema::plan_import(cdb, angles("elevation"));
  EXPECT_EQ(plan.manifest.times, (std::vector<double>{0, 5}));
  EXPECT_EQ(plan.manifest.task_count(), 1);
  EXPECT_EQ(plan.manifest.camera_count(), 2);
}

// Numeric columns that vary per image without indexing the images (an area, a maximum) are ignored
// with a warning naming them and --group-by, not made one task per image (then refused as "no image
// for camera ...").
TEST(WildCinema, PerImageMeasureColumnsAreIgnoredWithAWarning) {
  TempDir tmp("wild_cinema");
  const fs::path cdb = tmp / "m.cdb";
  std::string csv = "time,phi,theta,contour,area,max_value,FILE\n";
  int n = 0;
  for (int time : {0, 1})
    for (int phi : {0, 90})
      for (double contour : {0.25, 0.75}) {
        const std::string f = "img/" + std::to_string(n) + ".png";
        png(cdb / f, n);
        csv += std::to_string(time) + "," + std::to_string(phi) + ",0," + cinema::format_float(contour) + "," +
               std::to_string(1000 + 17 * n) + "." + std::to_string(n % 7) + "," + std::to_string(n % 3) + ".5," + f + "\n";
        ++n;
      }
  write_file(cdb / "data.csv", csv);
  const auto plan = cinema::plan_import(cdb, angles("elevation"));
  EXPECT_EQ(plan.manifest.task_count(), 2);  // the contour values
  ASSERT_EQ(plan.manifest.axes.size(), 1u);
  EXPECT_EQ(plan.manifest.axes[0].name, "contour");
  EXPECT_EQ(plan.manifest.times.size(), 2u);
  EXPECT_TRUE(has_warning(plan.warnings, {"data.csv", "area", "max_value", "per-image measures", "--group-by", "here contour"}))
      << joined(plan.warnings);
  // --group-by says the same without the warning.
  auto o = angles("elevation");
  o.group_by = {"contour"};
  const auto explicit_plan = cinema::plan_import(cdb, o);
  EXPECT_EQ(explicit_plan.manifest.task_count(), 2);
  EXPECT_TRUE(explicit_plan.warnings.empty()) << joined(explicit_plan.warnings);
}

// Rows whose FILE is not an image (cinema_python / ParaView .npz value or depth layers) are skipped
// with a warning naming the file and the count, not refused as "not a PNG or JPEG".
TEST(WildCinema, NonImageLayersAreSkippedWithAWarning) {
  TempDir tmp("wild_cinema");
  const fs::path cdb = tmp / "l.cdb";
  std::string csv = "time,phi,theta,layer,FILE\n";
  int n = 0;
  for (int phi : {0, 90}) {
    const std::string f = "img/" + std::to_string(phi) + ".png", d = "depth/" + std::to_string(phi) + ".npz";
    png(cdb / f, n++);
    write_file(cdb / d, "PK\x03\x04 not an image");
    csv += "0," + std::to_string(phi) + ",0,image," + f + "\n0," + std::to_string(phi) + ",0,depth," + d + "\n";
  }
  write_file(cdb / "data.csv", csv);
  const auto plan = cinema::plan_import(cdb, angles("elevation"));
  EXPECT_EQ(plan.manifest.camera_count(), 2);
  EXPECT_EQ(plan.manifest.task_count(), 1);
  EXPECT_TRUE(has_warning(plan.warnings, {"data.csv", "skipped 2 rows", "2 .npz", "line 3: depth/0.npz", "2 image rows imported"}))
      << joined(plan.warnings);
  // Only layers: refused naming what was found.
  write_file(cdb / "data.csv", "time,phi,theta,FILE\n0,0,0,depth/0.npz\n");
  const std::string e = error_of([&] { cinema::plan_import(cdb, angles("elevation")); });
  EXPECT_NE(e.find("no row names a PNG or JPEG image (1 .npz; e.g. "), std::string::npos) << e;
  EXPECT_NE(e.find("--image-column"), std::string::npos) << e;
}

// A second image per row (FILE and FILE2): the first image column is imported and the warning names
// the other and --image-column, which imports it instead.
TEST(WildCinema, SecondImageColumnIsNamedWithTheOptionToChoose) {
  TempDir tmp("wild_cinema");
  const fs::path cdb = tmp / "two.cdb";
  std::string csv = "time,phi,theta,FILE,FILE2\n";
  int n = 0;
  for (int phi : {0, 90}) {
    const std::string a = "rgb/" + std::to_string(phi) + ".png", b = "lum/" + std::to_string(phi) + ".png";
    png(cdb / a, n++);
    png(cdb / b, n++);
    csv += "0," + std::to_string(phi) + ",0," + a + "," + b + "\n";
  }
  write_file(cdb / "data.csv", csv);
  const auto plan = cinema::plan_import(cdb, angles("elevation"));
  EXPECT_EQ(plan.manifest.camera_count(), 2);
  EXPECT_EQ(plan.manifest.task_count(), 1);
  for (const auto& f : plan.files) EXPECT_EQ(f.parent_path().filename(), "rgb") << f;
  EXPECT_TRUE(has_warning(plan.warnings, {"data.csv line 2", "2 images (columns FILE, FILE2)", "imported FILE", "--image-column FILE2"}))
      << joined(plan.warnings);
  auto o = angles("elevation");
  o.image_column = "FILE2";
  const auto second = cinema::plan_import(cdb, o);
  for (const auto& f : second.files) EXPECT_EQ(f.parent_path().filename(), "lum") << f;
  EXPECT_TRUE(has_warning(second.warnings, {"images from column FILE2 (--image-column)", "FILE left out"})) << joined(second.warnings);
  o.image_column = "FILE3";
  EXPECT_NE(error_of([&] { cinema::plan_import(cdb, o); }).find("--image-column \"FILE3\" is not a column"), std::string::npos);
}

// cinema_python's layout image/{phi}/{theta}.png with the image column named FILE_png (as ParaView's
// extractor names it) was taken for a ParaView extractor: navigation mirrored, no warning. Evidence
// that disagrees is refused, naming both and the --angles values; the option imports it.
TEST(WildCinema, DisagreeingEvidenceIsRefusedNamingBoth) {
  TempDir tmp("wild_cinema");
  const fs::path cdb = tmp / "cp.cdb";
  std::string csv = "phi,theta,time,FILE_png\n";
  int n = 0;
  for (int phi : {0, 90, 180, 270})
    for (int theta : {-30, 30}) {
      const std::string f = "image/" + std::to_string(phi) + "/" + std::to_string(theta) + ".png";
      png(cdb / f, n++);
      csv += std::to_string(phi) + "," + std::to_string(theta) + ",0," + f + "\n";
    }
  write_file(cdb / "data.csv", csv);
  const std::string e = error_of([&] { cinema::plan_import(cdb); });
  EXPECT_EQ(e, (cdb / "data.csv").string() +
                   ": the evidence disagrees on how phi/theta were made: data.csv names its image column FILE_png (ParaView "
                   "image extractor), but the files laid out .../{phi}/{theta}.png (image/0/-30.png) as cinema_python names "
                   "them; say which with --angles paraview|cinema-python");
  const auto plan = cinema::plan_import(cdb, angles("cinema-python"));
  EXPECT_NE(plan.producer.find("cinema_python"), std::string::npos) << plan.producer;
  // cinema_python: phi 0 on -x (the camera at -x), where ParaView's extractor would put it on +z.
  const auto* c = camera_at(plan.manifest, "0", "-30");
  ASSERT_NE(c, nullptr);
  EXPECT_LT(c->position.x, -0.5);

  // The same with info.json saying cinema_python outright.
  write_file(cdb / "info.json", R"({"metadata": {"camera_model": "phi-theta"}})");
  const std::string e2 = error_of([&] { cinema::plan_import(cdb); });
  EXPECT_NE(e2.find("FILE_png (ParaView image extractor), but info.json metadata.camera_model is \"phi-theta\" (cinema_python); "
                    "say which with --angles paraview|cinema-python"),
            std::string::npos)
      << e2;
  // Evidence that agrees still imports without options (layout corroborates the image column).
  fs::remove_all(cdb);
  csv = "phi,producer,theta,time,FILE_png\n";
  for (int phi : {0, 90})
    for (int theta : {0, 30}) {
      char name[64];
      std::snprintf(name, sizeof name, "iso_000000p=%06.2ft=%06.2f.png", double(phi), double(theta));
      png(cdb / name, n++);
      csv += std::to_string(phi) + ",iso," + std::to_string(theta) + ",0," + name + "\n";
    }
  write_file(cdb / "data.csv", csv);
  const auto pv = cinema::plan_import(cdb);
  EXPECT_NE(pv.producer.find("ParaView image extractor"), std::string::npos) << pv.producer;
  EXPECT_NE(pv.producer.find("p={phi}t={theta}"), std::string::npos) << pv.producer;
}

// ParaView's camera mode Static writes no phi/theta: one camera, recorded or unknown, never a view
// made up from angles the database does not have.
TEST(WildCinema, StaticCameraIsImportedAsRecorded) {
  TempDir tmp("wild_cinema");
  const fs::path cdb = tmp / "static.cdb";
  std::string csv = "producer,time,FILE_png\n";
  for (int time : {0, 1}) {
    const std::string f = "RenderView1_00000" + std::to_string(time) + ".png";
    png(cdb / f, time);
    csv += "RenderView1," + std::to_string(time) + "," + f + "\n";
  }
  write_file(cdb / "data.csv", csv);
  const auto plan = cinema::plan_import(cdb);
  const auto& m = plan.manifest;
  ASSERT_EQ(m.camera_count(), 1);
  EXPECT_EQ(m.times.size(), 2u);
  EXPECT_EQ(m.cameras[0].labels.extra.at("cinema_position"), "unknown");
  EXPECT_EQ(m.rig.parameters.at("camera_position"), "unknown");
  EXPECT_EQ(m.rig.parameters.at("camera_mode"), "static");
  EXPECT_NE(plan.producer.find("ParaView image extractor (camera mode Static): one camera, its position not recorded"), std::string::npos)
      << plan.producer;
  EXPECT_TRUE(has_warning(plan.warnings, {"data.csv", "no phi, theta or camera column", "did not record"})) << joined(plan.warnings);
  // A recorded camera is taken as recorded.
  write_file(cdb / "info.json",
             R"({"metadata": {"camera_eye": [[3, 4, 5]], "camera_at": [[1, 1, 1]], "camera_up": [[0, 0, 1]], "camera_angle": [30]}})");
  const auto rec = cinema::plan_import(cdb);
  ASSERT_EQ(rec.manifest.camera_count(), 1);
  const auto& c = rec.manifest.cameras[0];
  EXPECT_EQ(c.position, (Vec3{3, 4, 5}));
  EXPECT_EQ(c.look_at, (Vec3{1, 1, 1}));
  EXPECT_NEAR(dot(c.up, normalize(c.look_at - c.position)), 0, 1e-12);
  EXPECT_GT(c.up.z, 0.5);
  EXPECT_EQ(c.labels.extra.count("cinema_position"), 0u);
  EXPECT_EQ(rec.manifest.rig.parameters.at("recorded_camera"), true);
}

// Older Ascent wrote theta as a latitude in -90..90; with --angles ascent it imports (polar angle
// 90 - theta) and says so. A range that is neither is refused naming it.
TEST(WildCinema, OlderAscentLatitudeThetaIsAcceptedAndSaid) {
  TempDir tmp("wild_cinema");
  const fs::path cdb = tmp / "ascent.cdb";
  std::string csv = "phi,theta,time,FILE\n";
  int n = 0;
  for (int phi : {0, 90})
    for (int theta : {-45, 0, 45}) {
      const std::string f = "0.0/" + std::to_string(phi) + "_" + std::to_string(theta) + "_c.png";
      png(cdb / f, n++);
      csv += std::to_string(phi) + "," + std::to_string(theta) + ",0.0," + f + "\n";
    }
  write_file(cdb / "data.csv", csv);
  const auto plan = cinema::plan_import(cdb, angles("ascent"));
  for (const char* theta : {"-45", "0", "45"}) {
    const auto* c = camera_at(plan.manifest, "0", theta);
    ASSERT_NE(c, nullptr) << theta;
    EXPECT_NEAR(c->labels.lat_deg, std::stod(theta), 1e-9) << theta;  // a latitude about Ascent's +z pole
  }
  EXPECT_NE(plan.producer.find("theta as a latitude"), std::string::npos) << plan.producer;
  EXPECT_TRUE(has_warning(plan.warnings, {"data.csv", "theta runs -45.0..45.0", "older Ascent", "90 - theta"})) << joined(plan.warnings);
  write_file(cdb / "data.csv", "phi,theta,time,FILE\n0,-45,0.0,0.0/0_-45_c.png\n0,120,0.0,0.0/0_0_c.png\n");
  const std::string e = error_of([&] { cinema::plan_import(cdb, angles("ascent")); });
  EXPECT_NE(e.find("data.csv: theta runs -45.0..120.0, neither a polar angle in 0..180 (Ascent) nor a latitude in -90..90"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("--angles"), std::string::npos) << e;
}
