// Cinema export and import: a round trip through Spec D, Spec D and Spec A databases laid out as
// ParaView and Ascent write them, and bad inputs with their messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "cinema/csv.hpp"
#include "cinema/export.hpp"
#include "cinema/import.hpp"
#include "core/error.hpp"
#include "core/png.hpp"
#include "store/database.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
namespace fs = std::filesystem;
using store::testing::TempDir;

namespace {

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
using store::testing::write_file;

// A smooth picture, as renderings are, that differs with every parameter: a gradient tinted by
// `tint` and a soft blob whose place follows phi/theta and whose size follows time.
Image picture(double phi, double theta, double time, int tint, int w = 48, int h = 40) {
  Image img(w, h, 3);
  const double cx = w * (0.5 + phi / 400.0), cy = h * (0.5 - theta / 200.0), r = 5 + 3 * time;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = img.at(x, y);
      const double b = std::exp(-((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (r * r));
      // Saturated, as a renderer's colours are (a wider picture used to wrap around past 255: a float
      // to integer conversion out of range, undefined behaviour that clang's UBSan reports).
      const auto byte = [](double v) { return std::uint8_t(std::clamp(v, 0.0, 255.0)); };
      p[0] = byte(40 + 2 * x + 150 * b);
      p[1] = byte(30 + 3 * y + 120 * b);
      p[2] = byte(60 + 50 * tint + 100 * b);
    }
  return img;
}

Image frame_of(const store::Database& db, int c, int t, int f) { return db.stream(c, t)->read_rgba(f); }

// Options with only some fields set (designated initializers would warn about the others).
cinema::ImportOptions grouped_by(std::vector<std::string> columns) {
  cinema::ImportOptions o;
  o.group_by = std::move(columns);
  return o;
}
cinema::ExportOptions export_options(std::vector<int> frames, std::string format = "png", bool overwrite = false) {
  cinema::ExportOptions o;
  o.frames = std::move(frames);
  o.format = std::move(format);
  o.overwrite = overwrite;
  return o;
}

using panoptes::store::testing::error_of;

// Cinema:View (cinemasci viewers 2.2, main.js) makes one slider per column whose first value is a
// number, starts every slider at its smallest value and shows the row matching all sliders: every
// image is reachable, and the first screen is one, when those columns identify each row exactly once
// and every combination of their values exists.
bool viewer_reaches_every_image(const cinema::CsvTable& t) {
  std::vector<std::size_t> keys;
  for (std::size_t c = 0; c < t.header.size(); ++c) {
    double x;
    if (t.header[c] != "FILE" && (t.rows[0][c].empty() || cinema::parse_number(t.rows[0][c], x))) keys.push_back(c);
  }
  std::set<std::vector<std::string>> combos;
  std::vector<std::set<std::string>> distinct(keys.size());
  for (const auto& row : t.rows) {
    std::vector<std::string> k;
    for (std::size_t i = 0; i < keys.size(); ++i) k.push_back(row[keys[i]]), distinct[i].insert(row[keys[i]]);
    combos.insert(k);
  }
  double product = 1;
  for (const auto& d : distinct) product *= double(d.size());
  return combos.size() == t.rows.size() && product == double(t.rows.size());
}

}  // namespace

TEST(CinemaExport, WritesSpecDAndImportReadsTheSameDatabaseBack) {
  TempDir tmp("cinema");
  store::SyntheticOptions so;
  so.cameras = 5;
  so.tasks = 3;
  so.frames = 3;
  so.width = 64;
  so.height = 48;
  so.video.gop = 1;
  store::write_synthetic_database(tmp / "db", so);
  const auto report = cinema::export_cinema(tmp / "db", tmp / "out.cdb", export_options({0, 2}));
  EXPECT_EQ(report.images, 5 * 3 * 2);

  // data.csv: the identifying columns, FILE last; shortest decimals; CRLF rows (RFC 4180). Five
  // Fibonacci cameras are no phi/theta grid: one camera column; the tasks are the isovalue axis.
  const std::string csv = read_file(tmp / "out.cdb/data.csv");
  ASSERT_TRUE(csv.starts_with("time,camera,task_name,isovalue,FILE\r\n")) << csv.substr(0, 200);
  const auto table = cinema::parse_csv(csv, "data.csv");
  ASSERT_EQ(table.rows.size(), 30u);
  EXPECT_EQ(table.rows[0][0], "0");
  EXPECT_EQ(table.rows[0][4], "image/c0/t0_f0.png");
  EXPECT_TRUE(fs::exists(tmp / "out.cdb/image/c4/t2_f2.png"));
  EXPECT_FALSE(fs::exists(tmp / "out.cdb/image/c4/t2_f1.png"));
  EXPECT_TRUE(viewer_reaches_every_image(table));

  // The round trip restores cameras, shells, graph, rig and tasks exactly (panoptes-cinema.json).
  cinema::import_cinema(tmp / "out.cdb", tmp / "back");
  const auto a = store::Database::open(tmp / "db");
  const auto b = store::Database::open(tmp / "back");
  ASSERT_EQ(b.frame_count(), 2);
  EXPECT_EQ(b.manifest().times, (std::vector<double>{a.manifest().frame_time(0), a.manifest().frame_time(2)}));
  EXPECT_EQ(b.manifest().cameras, a.manifest().cameras);
  EXPECT_EQ(b.manifest().graph.neighbours, a.manifest().graph.neighbours);
  EXPECT_EQ(b.manifest().rig, a.manifest().rig);
  EXPECT_EQ(b.manifest().tasks, a.manifest().tasks);
  EXPECT_EQ(b.manifest().axes, a.manifest().axes);
  double worst = 1e9;
  for (int c = 0; c < 5; ++c)
    for (int t = 0; t < 3; ++t)
      for (int f = 0; f < 2; ++f) worst = std::min(worst, psnr(frame_of(a, c, t, 2 * f), frame_of(b, c, t, f)));
  EXPECT_GE(worst, 40.0) << "round-trip PSNR";

  // JPEG export: smaller files, still a faithful picture; an existing export needs --overwrite.
  EXPECT_NE(error_of([&] { cinema::export_cinema(tmp / "db", tmp / "out.cdb", {}); }).find("use --overwrite"),
            std::string::npos);
  cinema::export_cinema(tmp / "db", tmp / "out.cdb", export_options({}, "jpg", true));
  EXPECT_TRUE(fs::exists(tmp / "out.cdb/image/c0/t0_f1.jpg"));
  EXPECT_FALSE(fs::exists(tmp / "out.cdb/image/c0/t0_f0.png"));
  EXPECT_GE(psnr(read_image((tmp / "out.cdb/image/c1/t1_f1.jpg").string()), frame_of(a, 1, 1, 1)), 30.0);
}

// Cameras on a longitude x latitude grid over two shells, tasks that are not their axis' grid: the
// viewer's sliders are phi, theta, shell, task and time, and every combination is exactly one image.
TEST(CinemaExport, GridCamerasWithShellsAndTaskIds) {
  TempDir tmp("cinema");
  store::SyntheticOptions so;
  so.cameras = 16;
  so.tasks = 2;
  so.frames = 2;
  so.width = 48;
  so.height = 40;
  store::Manifest m = store::synthetic_manifest(so);
  for (int c = 0; c < 16; ++c) {
    auto& e = m.cameras[std::size_t(c)];
    e.labels.lon_deg = -180 + 90 * (c % 4);
    e.labels.lat_deg = (c / 4) % 2 ? 30.000000000000004 : -30;  // trigonometry noise prints as 30
    e.labels.shell = c / 8;
    e.labels.patch = "latlon";
  }
  m.tasks[1].axes.clear();  // task 1 off the axis: the axis does not identify the tasks
  m.rig.kind = "latlon";
  m.rig.parameters = {{"nlat", 2}, {"nlon", 4}, {"radii", {3.0, 2.0}}};
  {
    store::DatabaseWriter w = store::DatabaseWriter::create(tmp / "db", m, false);
    for (int c = 0; c < 16; ++c)
      for (int t = 0; t < 2; ++t) {
        for (int f = 0; f < 2; ++f) w.append(c, t, store::synthetic_frame(c, t, f, 48, 40));
        w.close_stream(c, t);
      }
    w.set_time(0, m.times[0]);
    w.set_time(1, m.times[1]);
    w.finalize();
  }
  cinema::export_cinema(tmp / "db", tmp / "out.cdb");
  const std::string csv = read_file(tmp / "out.cdb/data.csv");
  ASSERT_TRUE(csv.starts_with("time,phi,theta,shell,task,task_name,FILE\r\n")) << csv.substr(0, 200);
  const auto table = cinema::parse_csv(csv, "data.csv");
  EXPECT_EQ(table.rows[0][1], "-180");
  EXPECT_EQ(table.rows[8][2], "30");
  EXPECT_TRUE(viewer_reaches_every_image(table));
  cinema::import_cinema(tmp / "out.cdb", tmp / "back");
  const auto a = store::Database::open(tmp / "db");
  const auto b = store::Database::open(tmp / "back");
  EXPECT_EQ(b.manifest().cameras, a.manifest().cameras);
  EXPECT_EQ(b.manifest().graph.neighbours, a.manifest().graph.neighbours);
  EXPECT_EQ(b.manifest().rig, a.manifest().rig);
  EXPECT_EQ(b.manifest().tasks, a.manifest().tasks);
  EXPECT_GE(psnr(frame_of(a, 13, 1, 1), frame_of(b, 13, 1, 1)), 40.0);
}

TEST(CinemaExport, ParsesFrameLists) {
  EXPECT_EQ(cinema::parse_frame_list("0,3,5:9:2,:2", 10), (std::vector<int>{0, 3, 5, 7, 0, 1}));
  EXPECT_EQ(error_of([] { cinema::parse_frame_list("12", 10); }),
            "--frames: frame 12 out of range; the database has 10 complete frames (0..9)");
  EXPECT_NE(error_of([] { cinema::parse_frame_list("a:b", 10); }).find("is not a frame"), std::string::npos);
}

// ParaView's Spec D export: data.csv with time, phi, theta and a pipeline parameter, FILE last, the
// images in per-time directories.
TEST(CinemaImport, ParaViewSpecD) {
  TempDir tmp("cinema");
  const fs::path cdb = tmp / "paraview.cdb";
  std::string csv = "time,phi,theta,contour,FILE\n";
  const std::vector<double> phis{-180, -120, -60, 0, 60, 120}, thetas{-45, 0, 45}, times{0.0, 0.5};
  for (double time : times)
    for (double phi : phis)
      for (double theta : thetas)
        for (int k = 0; k < 2; ++k) {
          const std::string file = "image/" + cinema::format_float(time) + "/" + std::to_string(int(phi)) + "_" +
                                   std::to_string(int(theta)) + "_" + std::to_string(k) + ".png";
          fs::create_directories((cdb / file).parent_path());
          write_png((cdb / file).string(), picture(phi, theta, time, k));
          csv += cinema::format_float(time) + "," + std::to_string(int(phi)) + "," + std::to_string(int(theta)) + "," +
                 (k ? "0.75" : "0.25") + "," + file + "\n";
        }
  write_file(cdb / "data.csv", csv);

  // Generic angles: refused until the convention is given.
  EXPECT_NE(error_of([&] { cinema::plan_import(cdb); }).find("--angles"), std::string::npos);
  cinema::ImportOptions elevation;
  elevation.angles = "elevation";
  cinema::import_cinema(cdb, tmp / "db", elevation);
  const auto db = store::Database::open(tmp / "db");
  const auto& m = db.manifest();
  ASSERT_EQ(db.camera_count(), 18);
  ASSERT_EQ(db.task_count(), 2);
  ASSERT_EQ(db.frame_count(), 2);
  EXPECT_EQ(m.times, times);
  ASSERT_EQ(m.axes.size(), 1u);
  EXPECT_EQ(m.axes[0].name, "contour");
  EXPECT_EQ(m.axes[0].values, (std::vector<double>{0.25, 0.75}));
  EXPECT_EQ(m.tasks[1].name, "contour=0.75");
  EXPECT_EQ(m.step_task_on_axis(0, "contour", 1), 1);
  EXPECT_EQ(m.image.width, 48);
  // Cameras numbered from the north ring down, each ring by phi; directions from phi/theta.
  EXPECT_EQ(m.cameras[0].labels.lat_deg, 45);
  EXPECT_EQ(m.cameras[0].labels.lon_deg, -180);
  for (int c = 0; c < 18; ++c) {
    const auto& e = m.cameras[c];
    const Vec3 d = e.position - e.look_at;
    const double lat = std::atan2(d.z, std::hypot(d.x, d.y)) * 180 / M_PI;
    EXPECT_NEAR(lat, e.labels.lat_deg, 1e-9);
    // The graph: left and right neighbours stay on the ring (same theta), and exist for every camera.
    const auto& n = m.graph.neighbours[c];
    ASSERT_GE(n.left, 0);
    ASSERT_GE(n.right, 0);
    EXPECT_EQ(m.cameras[n.left].labels.lat_deg, e.labels.lat_deg) << c;
    EXPECT_EQ(m.cameras[n.right].labels.lat_deg, e.labels.lat_deg) << c;
    // On the equator ring, up and down lead to the rings above and below.
    if (e.labels.lat_deg == 0) {
      ASSERT_GE(n.up, 0);
      ASSERT_GE(n.down, 0);
      EXPECT_EQ(m.cameras[n.up].labels.lat_deg, 45) << c;
      EXPECT_EQ(m.cameras[n.down].labels.lat_deg, -45) << c;
    }
  }
  // Frames are the images (camera 8 = theta 0, phi -60; task 1 = contour 0.75; time 0.5).
  EXPECT_EQ(m.cameras[8].labels.lat_deg, 0);
  EXPECT_EQ(m.cameras[8].labels.lon_deg, -60);
  EXPECT_GE(psnr(frame_of(db, 8, 1, 1), picture(-60, 0, 0.5, 1)), 40.0);
}

// The older Spec A layout ParaView and Ascent still write: info.json with parameter_list and
// name_pattern "{time}/{phi}_{theta}.png"; here with an extra option parameter (a named variable).
TEST(CinemaImport, AscentSpecA) {
  TempDir tmp("cinema");
  const fs::path cdb = tmp / "ascent.cdb";
  const std::vector<int> phis{0, 90, 180, 270}, thetas{-60, 0, 60};
  const std::vector<std::string> times{"0", "100", "200"}, vars{"pressure", "velocity"};
  for (std::size_t ti = 0; ti < times.size(); ++ti)
    for (int phi : phis)
      for (int theta : thetas)
        for (std::size_t v = 0; v < vars.size(); ++v) {
          const fs::path f = cdb / times[ti] / (std::to_string(phi) + "_" + std::to_string(theta) + "_" + vars[v] + ".png");
          fs::create_directories(f.parent_path());
          write_png(f.string(), picture(phi - 180, theta, double(ti), int(v)));
        }
  write_file(cdb / "info.json", R"({
  "type": "simple", "version": "1.1", "metadata": {"type": "parametric-image-stack"},
  "name_pattern": "{time}/{phi}_{theta}_{var}.png",
  "parameter_list": {
    "time": {"default": "0", "label": "time", "type": "range", "values": ["0", "100", "200"]},
    "phi": {"default": 0, "label": "phi", "type": "range", "values": [0, 90, 180, 270]},
    "theta": {"default": 0, "label": "theta", "type": "range", "values": [-60, 0, 60]},
    "var": {"default": "pressure", "label": "var", "type": "option", "values": ["pressure", "velocity"]}
  }
})");
  cinema::ImportOptions elevation;
  elevation.angles = "elevation";
  const auto r = cinema::import_cinema(cdb, tmp / "db", elevation);
  EXPECT_EQ(r.spec, "A");
  const auto db = store::Database::open(tmp / "db");
  const auto& m = db.manifest();
  ASSERT_EQ(db.camera_count(), 12);
  ASSERT_EQ(db.task_count(), 2);
  ASSERT_EQ(db.frame_count(), 3);
  EXPECT_EQ(m.times, (std::vector<double>{0, 100, 200}));
  EXPECT_TRUE(m.axes.empty());
  EXPECT_EQ(m.tasks[0].name, "var=pressure");
  EXPECT_EQ(m.tasks[1].name, "var=velocity");
  // Camera 5: the middle ring (theta 0), second by phi (90).
  EXPECT_EQ(m.cameras[5].labels.lat_deg, 0);
  EXPECT_EQ(m.cameras[5].labels.lon_deg, 90);
  EXPECT_GE(psnr(frame_of(db, 5, 1, 2), picture(90 - 180, 0, 2, 1)), 40.0);
  auto by_var = grouped_by({"var"});
  by_var.angles = "elevation";
  EXPECT_EQ(cinema::plan_import(cdb, by_var).manifest.task_count(), 2);
  auto nosuch = grouped_by({"nosuch"});
  nosuch.angles = "elevation";
  const std::string e = error_of([&] { cinema::import_cinema(cdb, tmp / "db2", nosuch); });
  EXPECT_NE(e.find("--group-by column \"nosuch\" does not exist; columns: phi, theta, time, var"), std::string::npos) << e;
}

TEST(CinemaImport, RefusesBadInputsWithClearMessages) {
  TempDir tmp("cinema");
  const fs::path cdb = tmp / "bad.cdb";
  auto make = [&](const std::string& rows) {
    fs::remove_all(cdb);
    fs::create_directories(cdb);
    write_png((cdb / "a.png").string(), picture(0, 0, 0, 0));
    write_png((cdb / "b.png").string(), picture(90, 0, 0, 0));
    write_png((cdb / "small.png").string(), picture(0, 0, 0, 0, 32, 32));
    write_file(cdb / "data.csv", "time,phi,theta,FILE\n" + rows);
  };
  cinema::ImportOptions elevation;
  elevation.angles = "elevation";
  auto import_error = [&] { return error_of([&] { cinema::plan_import(cdb, elevation); }); };
  const std::string where = (cdb / "data.csv").string();

  make("0,0,0,a.png\n0,90,0,small.png\n");
  EXPECT_EQ(import_error(), (cdb / "small.png").string() + ": image is 32x32, but a.png is 48x40; a Panoptes database has one image size");

  make("0,0,0,a.png\n0,90,0,gone.png\n");
  EXPECT_EQ(import_error(), where + " line 3: image \"gone.png\" does not exist (" + (fs::weakly_canonical(cdb) / "gone.png").string() + ")");

  make("0,0,0,a.png\n0,east,0,b.png\n");
  EXPECT_EQ(import_error(), where + " line 3: phi \"east\" (column phi) is not a number");

  make("0,0,0,a.png\n0,90,x,b.png\n");
  EXPECT_EQ(import_error(), where + " line 3: theta \"x\" (column theta) is not a number");

  write_png((tmp / "outside.png").string(), picture(0, 0, 0, 0));
  make("0,0,0,a.png\n0,90,0,../outside.png\n");
  EXPECT_NE(import_error().find("line 3: FILE \"../outside.png\" resolves to"), std::string::npos) << import_error();
  EXPECT_NE(import_error().find("outside the database"), std::string::npos);

  make("0,0,0,a.png\n0,90,0," + (tmp / "outside.png").string() + "\n");
  EXPECT_NE(import_error().find("is an absolute path"), std::string::npos) << import_error();

  make("0,0,0,a.png\n0,90,0,link.png\n");
  fs::create_symlink(tmp / "outside.png", cdb / "link.png");
  EXPECT_NE(import_error().find("outside the database"), std::string::npos) << import_error();

  make("0,0,0,a.png\n1,0,0,a.png\n0,90,0,b.png\n");
  EXPECT_EQ(import_error(), where + ": no image for camera phi=90.0 theta=0.0, task \"image\", time 1.0; every camera needs every task at every time");

  make("0,0,0,a.png\n0,0,0,b.png\n");
  EXPECT_EQ(import_error(), where + " line 3: same camera, task and time as " + where + " line 2: two images for one view");

  // Rows that differ only in a column left out of --group-by.
  fs::remove(cdb / "data.csv");
  write_file(cdb / "data.csv", "time,phi,theta,var,level,FILE\n0,0,0,p,1,a.png\n0,0,0,p,2,b.png\n");
  auto by_var = grouped_by({"var"});
  by_var.angles = "elevation";
  EXPECT_EQ(error_of([&] { cinema::plan_import(cdb, by_var); }),
            where + " line 3: same camera, task and time as " + where + " line 2; they differ in level: add it to --group-by");

  make("0,0,120,a.png\n");
  EXPECT_EQ(import_error(), where + ": theta 120.0 is not an elevation in -90..90 degrees; say how its angles were made with "
                            "--angles paraview|cinema-python|ascent|elevation (and, for elevation, --azimuth-zero +x|-x)");

  fs::remove(cdb / "data.csv");
  EXPECT_EQ(import_error(), cdb.string() + ": neither data.csv (Cinema Spec D) nor info.json (Spec A) found; not a Cinema database");
  write_file(cdb / "info.json", R"({"name_pattern": "{time}/{phi}.png", "parameter_list": {"time": {"values": [0]}}})");
  EXPECT_EQ(import_error(), (cdb / "info.json").string() + ": name_pattern \"{time}/{phi}.png\" uses {phi}, which is not a parameter");
}
