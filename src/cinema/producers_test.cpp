// Databases that the real producers wrote (src/cinema/fixtures: ParaView 5.11 pvbatch output, and
// Ascent's convention rendered by ParaView) import without options, and every imported camera is the
// camera the producer used: ParaView's own vtkCamera, recorded per image in cameras.json by the
// scripts that made the fixtures.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "cinema/csv.hpp"
#include "cinema/export.hpp"
#include "cinema/image_file.hpp"
#include "cinema/import.hpp"
#include "core/error.hpp"
#include "store/database.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
namespace fs = std::filesystem;

namespace {

const fs::path kFixtures = PANOPTES_CINEMA_FIXTURES;

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0, 1.0)) * 180 / M_PI;
}
Vec3 vec(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }
Vec3 orthogonal(const Vec3& up, const Vec3& forward) { return normalize(up - forward * dot(up, forward)); }
double number(const nlohmann::json& v) { return v.is_string() ? std::stod(v.get<std::string>()) : v.get<double>(); }

struct Checked {
  int images = 0, turned = 0;
  double worst_dir = 0, worst_up = 0, worst_pos = 0;
};

// Compares every recorded producer camera with the imported camera of the same (phi, theta).
// Positions: absolute when the database records the scene (positions_recorded), else after mapping
// the producer's scene onto the import's stand-in scene.
Checked compare_cameras(const cinema::ImportPlan& plan, const fs::path& cdb, bool positions_recorded) {
  std::ifstream in(cdb / "cameras.json");
  const auto rec = nlohmann::json::parse(in);
  const auto& m = plan.manifest;
  Checked out;
  for (const auto& img : rec["images"]) {
    const double phi = number(img["phi"]), theta = number(img["theta"]);
    int id = -1;
    for (const auto& c : m.cameras)
      if (std::stod(c.labels.extra.at("cinema_phi")) == phi && std::stod(c.labels.extra.at("cinema_theta")) == theta) id = c.id;
    EXPECT_GE(id, 0) << "no imported camera for phi " << phi << " theta " << theta;
    if (id < 0) continue;
    const auto& c = m.cameras[std::size_t(id)];
    const Vec3 pos = vec(img["position"]), focal = vec(img["focal_point"]);
    const Vec3 fwd_p = normalize(focal - pos), fwd_i = normalize(c.look_at - c.position);
    const Vec3 up_p = orthogonal(vec(img["view_up"]), fwd_p), up_i = orthogonal(c.up, fwd_i);
    const bool turned = c.labels.extra.count("cinema_turned") > 0;
    out.turned += turned;
    out.worst_dir = std::max(out.worst_dir, angle_deg(fwd_p, fwd_i));
    // A turned camera's picture was stored rotated by 180 degrees: its up is the producer's, negated.
    out.worst_up = std::max(out.worst_up, angle_deg(turned ? -up_p : up_p, up_i));
    // The producer's up pointed away from its pole exactly when the picture was turned.
    EXPECT_EQ(turned, dot(up_p, vec(m.rig.parameters["pole"])) < -1e-9) << "phi " << phi << " theta " << theta;
    if (positions_recorded) {
      out.worst_pos = std::max(out.worst_pos, norm(c.position - pos) / norm(pos - focal));
    } else {
      // The database records no scene: the import frames a stand-in (a unit box at the origin) as the
      // producer frames its own. Map the producer's scene (the bounds it framed, recorded by the
      // fixture's script) onto the stand-in by the similarity that takes one bounding sphere to the
      // other; the producer's camera must then land on the imported one, focal point and distance.
      const auto& b = img.at("scene_bounds");
      const Vec3 lo{b[0].get<double>(), b[2].get<double>(), b[4].get<double>()};
      const Vec3 hi{b[1].get<double>(), b[3].get<double>(), b[5].get<double>()};
      const double scale = (std::sqrt(3.0) / 2) / (norm(hi - lo) / 2);
      const Vec3 mid = (lo + hi) * 0.5;
      const double dist = norm(c.position - c.look_at);
      out.worst_pos = std::max(out.worst_pos, norm((pos - mid) * scale - c.position) / dist);
      out.worst_pos = std::max(out.worst_pos, norm((focal - mid) * scale - c.look_at) / dist);
    }
    ++out.images;
  }
  std::printf("%s: %d images, worst direction %.2g deg, up %.2g deg, position %.2g of the distance\n",
              cdb.filename().c_str(), out.images, out.worst_dir, out.worst_up, out.worst_pos);
  return out;
}

// → / ← / ↑ / ↓ go to the camera lying towards the image's right / left / top / bottom edge, as in a
// native database, and the mini-map (longitude across, latitude up) agrees for cameras off the poles.
void check_navigation(const store::Manifest& m) {
  int checked = 0;
  for (const auto& c : m.cameras) {
    const Vec3 fwd = normalize(c.look_at - c.position), up = orthogonal(c.up, fwd), right = cross(fwd, up);
    const auto& n = m.graph.neighbours[std::size_t(c.id)];
    auto towards = [&](int j, const Vec3& axis) { return dot(m.cameras[std::size_t(j)].position - c.position, axis); };
    if (n.right >= 0) {
      EXPECT_GT(towards(n.right, right), 0) << "camera " << c.id;
    }
    if (n.left >= 0) {
      EXPECT_LT(towards(n.left, right), 0) << "camera " << c.id;
    }
    if (n.up >= 0) {
      EXPECT_GT(towards(n.up, up), 0) << "camera " << c.id;
    }
    if (n.down >= 0) {
      EXPECT_LT(towards(n.down, up), 0) << "camera " << c.id;
    }
    if (n.right >= 0 && std::abs(c.labels.lat_deg) < 75 && std::abs(m.cameras[std::size_t(n.right)].labels.lat_deg) < 75) {
      double dlon = m.cameras[std::size_t(n.right)].labels.lon_deg - c.labels.lon_deg;
      dlon = std::remainder(dlon, 360.0);
      EXPECT_GT(dlon, 0) << "mini-map: camera " << c.id << " -> " << n.right;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

}  // namespace

TEST(CinemaProducers, ParaViewExtractsSpecDPhiTheta) {
  const fs::path cdb = kFixtures / "paraview_extracts.cdb";
  const auto plan = cinema::plan_import(cdb);
  EXPECT_NE(plan.producer.find("ParaView image extractor"), std::string::npos) << plan.producer;
  EXPECT_NE(plan.producer.find("FILE_png"), std::string::npos) << plan.producer;
  const auto& m = plan.manifest;
  EXPECT_EQ(m.camera_count(), 12);  // PhiResolution 4 x ThetaResolution 3
  EXPECT_EQ(m.task_count(), 2);     // the two extractors (contour values), column "producer"
  EXPECT_EQ(m.times.size(), 3u);
  const Checked k = compare_cameras(plan, cdb, false);
  EXPECT_EQ(k.images, 24);
  EXPECT_EQ(k.turned, 16);  // theta 120 and 240 look over the pole: upside down in ParaView
  EXPECT_LT(k.worst_dir, 1.0);
  EXPECT_LT(k.worst_up, 5.0);
  EXPECT_LT(k.worst_pos, 0.01);
  check_navigation(m);
  // The distance follows vtkRenderer::ResetCamera's framing (bounding sphere / sin(view angle / 2)).
  const auto& c0 = m.cameras[0];
  EXPECT_NEAR(norm(c0.position - c0.look_at) * std::sin(15 * M_PI / 180), std::sqrt(3.0) / 2, 1e-9);
}

TEST(CinemaProducers, ParaViewCinemaPythonSpecAContourSweep) {
  const fs::path cdb = kFixtures / "paraview_cinema_python.cdb";
  const auto plan = cinema::plan_import(cdb);
  EXPECT_EQ(plan.spec, "A");
  EXPECT_NE(plan.producer.find("cinema_python"), std::string::npos) << plan.producer;
  const auto& m = plan.manifest;
  EXPECT_EQ(m.camera_count(), 12);
  ASSERT_EQ(m.axes.size(), 1u);
  EXPECT_EQ(m.axes[0].name, "Contour1");
  EXPECT_EQ(m.axes[0].values, (std::vector<double>{150, 175, 200}));
  EXPECT_EQ(m.times, (std::vector<double>{0, 1, 2}));
  EXPECT_EQ(m.rig.parameters["recorded_camera"], true);
  const Checked k = compare_cameras(plan, cdb, true);  // the metadata records eye, focal point and up
  EXPECT_EQ(k.images, 108);
  EXPECT_EQ(k.turned, 0);
  EXPECT_LT(k.worst_dir, 1.0);
  EXPECT_LT(k.worst_up, 5.0);
  EXPECT_LT(k.worst_pos, 0.01);
  check_navigation(m);
}

TEST(CinemaProducers, AscentConvention) {
  const fs::path cdb = kFixtures / "ascent_convention.cdb";
  const auto plan = cinema::plan_import(cdb);
  EXPECT_NE(plan.producer.find("Ascent"), std::string::npos) << plan.producer;
  const auto& m = plan.manifest;
  EXPECT_EQ(m.camera_count(), 12);
  const Checked k = compare_cameras(plan, cdb, false);
  EXPECT_EQ(k.images, 24);
  EXPECT_LT(k.worst_dir, 1.0);
  EXPECT_LT(k.worst_up, 5.0);
  EXPECT_LT(k.worst_pos, 0.01);
  check_navigation(m);
  // theta is polar: theta 0 looks down from +z (latitude 90), theta 120 from below the equator.
  for (const auto& c : m.cameras) {
    const double theta = std::stod(c.labels.extra.at("cinema_theta"));
    EXPECT_NEAR(c.labels.lat_deg, 90 - theta, 1e-9) << c.id;
  }
}

TEST(CinemaProducers, TurnedPicturesAreStoredUpright) {
  store::testing::TempDir tmp("cinema_producers");
  const fs::path cdb = kFixtures / "paraview_extracts.cdb";
  const auto r = cinema::import_cinema(cdb, tmp / "db");
  const auto db = store::Database::open(tmp / "db");
  const auto& m = db.manifest();
  int turned = -1, straight = -1;
  for (const auto& c : m.cameras) (c.labels.extra.count("cinema_turned") ? turned : straight) = c.id;
  ASSERT_GE(turned, 0);
  ASSERT_GE(straight, 0);
  auto psnr_to = [&](int cam, bool rotate) {
    const std::string phi = m.cameras[std::size_t(cam)].labels.extra.at("cinema_phi");
    const std::string theta = m.cameras[std::size_t(cam)].labels.extra.at("cinema_theta");
    char name[128];
    std::snprintf(name, sizeof name, "iso150_000000p=%06.2ft=%06.2f.png", std::stod(phi), std::stod(theta));
    const Image want = cinema::decode_image(cdb / name, rotate);
    const Image got = db.stream(cam, 0)->read_rgba(0);
    return psnr(want, got);
  };
  EXPECT_GE(psnr_to(turned, true), 30.0);
  EXPECT_LT(psnr_to(turned, false), psnr_to(turned, true) - 3);
  EXPECT_GE(psnr_to(straight, false), 30.0);
  EXPECT_EQ(r.cameras, 12);
}

// Without evidence of the producer, phi/theta are ambiguous: refused with the option to pass.
TEST(CinemaProducers, UnknownConventionAsksForAnOption) {
  store::testing::TempDir tmp("cinema_producers");
  const fs::path cdb = tmp / "x.cdb";
  fs::create_directories(cdb);
  // Ascent's data.csv alone (its info.json and info.js lost): thetas 0 and 60 would fit an elevation.
  fs::copy_file(kFixtures / "ascent_convention.cdb/0.0/-180.0_0.0_contour.png", cdb / "a.png");
  fs::copy_file(kFixtures / "ascent_convention.cdb/0.0/-180.0_60.0_contour.png", cdb / "b.png");
  std::ofstream(cdb / "data.csv") << "phi,theta,time,FILE\n-180.0,0.0,0.0,a.png\n-180.0,60.0,0.0,b.png\n";
  const std::string e = store::testing::error_of([&] { cinema::plan_import(cdb); });
  EXPECT_NE(e.find("cannot tell which producer"), std::string::npos) << e;
  EXPECT_NE(e.find("--angles paraview|cinema-python|ascent|elevation"), std::string::npos) << e;
  cinema::ImportOptions o;
  o.angles = "ascent";
  const auto plan = cinema::plan_import(cdb, o);
  auto camera_at_theta = [](const cinema::ImportPlan& p, const std::string& theta) {
    for (const auto& c : p.manifest.cameras)
      if (c.labels.extra.at("cinema_theta") == theta) return c;
    ADD_FAILURE() << "no camera at theta " << theta;
    return store::CameraEntry{};
  };
  EXPECT_NEAR(camera_at_theta(plan, "0.0").labels.lat_deg, 90, 1e-9);  // theta 0 = the +z pole
  o.angles = "elevation";
  o.azimuth_zero = "-x";
  const auto mirrored = cinema::plan_import(cdb, o);
  const auto flat = camera_at_theta(mirrored, "0.0");
  EXPECT_NEAR(normalize(flat.position - flat.look_at).x, 1, 1e-9);  // phi -180 counted from -x: +x
  o.azimuth_zero = "+y";
  EXPECT_NE(store::testing::error_of([&] { cinema::plan_import(cdb, o); }).find("--azimuth-zero \"+y\""), std::string::npos);
}

// A producer's database survives export-cinema → import-cinema: the cameras (turned ones with their
// labels), the graph, the rig with the producer's pole (the mini-map draws about it) and the frames.
TEST(CinemaProducers, ImportedParaViewExtractsRoundTrip) {
  store::testing::TempDir tmp("cinema_producers");
  cinema::import_cinema(kFixtures / "paraview_extracts.cdb", tmp / "db");
  cinema::export_cinema(tmp / "db", tmp / "out.cdb");
  cinema::import_cinema(tmp / "out.cdb", tmp / "back");
  const auto a = store::Database::open(tmp / "db");
  const auto b = store::Database::open(tmp / "back");
  EXPECT_EQ(b.manifest().cameras, a.manifest().cameras);
  EXPECT_EQ(b.manifest().graph.neighbours, a.manifest().graph.neighbours);
  EXPECT_EQ(b.manifest().rig, a.manifest().rig);
  EXPECT_EQ(b.manifest().rig.parameters["pole"], (nlohmann::json{0, 1, 0}));
  EXPECT_EQ(b.manifest().tasks, a.manifest().tasks);
  EXPECT_EQ(b.manifest().times, a.manifest().times);
  double worst = 1e9;
  for (int c = 0; c < a.manifest().camera_count(); ++c)
    for (int t = 0; t < a.manifest().task_count(); ++t)
      for (int f = 0; f < a.frame_count(); ++f) worst = std::min(worst, psnr(a.stream(c, t)->read_rgba(f), b.stream(c, t)->read_rgba(f)));
  EXPECT_GE(worst, 40.0) << "round-trip PSNR";
}
