// Databases imported from the real Cinema producers (src/cinema/fixtures: ParaView 5.11's image
// extractor, Spec D; ParaView's cinema_python, Spec A; Ascent's convention) turn the object under
// →, a mouse drag and the mini-map exactly as a native Panoptes database does. Each gesture is played
// on the real pieces: player::Engine (→ and the snap a drag asks for), ui::DragRotation (the drag
// rule of the window), ui::minimap_directions + project_to_map (what the mini-map draws).
//
// "How the object turns" is measured on the pictures' geometry: take the point of the object that
// faces the current camera (its front) and see where it lands in the next camera's picture. → moves
// the camera towards the picture's right edge, so the front goes left; a drag to the right grabs the
// object and turns its front to the right (docs/ui.md). A mirrored drag, a mirrored graph or a
// mini-map drawn about the wrong pole each fail here.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "camera/navigation.hpp"
#include "camera/rig_spec.hpp"
#include "cinema/import.hpp"
#include "player/engine.hpp"
#include "player/test_db.hpp"
#include "ui/drag_rotation.hpp"
#include "ui/hud.hpp"
#include "ui/minimap.hpp"

using namespace panoptes;
namespace fs = std::filesystem;

namespace {

const fs::path kFixtures = PANOPTES_CINEMA_FIXTURES;

Vec3 view_up(const store::CameraEntry& c) {
  const Vec3 f = normalize(c.look_at - c.position);
  return normalize(c.up - f * dot(c.up, f));
}

// Horizontal position (tangent of the angle, > 0 = right of centre) in camera `to`'s picture of the
// object's point that faces camera `from` (a quarter of the way from the look-at point to `from`).
double front_x(const store::Manifest& m, int from, int to) {
  const auto& a = m.cameras[std::size_t(from)];
  const auto& b = m.cameras[std::size_t(to)];
  const Vec3 front = a.look_at + (a.position - a.look_at) * 0.25;
  const Vec3 fwd = normalize(b.look_at - b.position), right = cross(fwd, view_up(b));
  const Vec3 v = front - b.position;
  return dot(v, right) / dot(v, fwd);
}

struct Turned {
  int cameras = 0;  // cameras off the poles whose three gestures were checked
};

// Plays → and a rightward drag from every camera off the poles that has a left and a right neighbour.
Turned check_gestures(const fs::path& db) {
  player::EngineOptions o;
  o.prefetch = false;
  o.start_playing = false;
  player::Engine e(db, o);
  const store::Manifest& m = e.manifest();
  const std::vector<Vec3> map = ui::minimap_directions(m);
  const double map_elevation = 25 * M_PI / 180;  // as the mini-map looks (only x is compared: any)
  Turned out;
  for (const auto& c : m.cameras) {
    const auto& n = m.graph.neighbours[std::size_t(c.id)];
    if (std::abs(c.labels.lat_deg) >= 75 || n.right < 0 || n.left < 0) continue;
    SCOPED_TRACE("camera " + std::to_string(c.id) + " of " + db.filename().string());
    // The mini-map turns to the current camera's longitude (MiniMap::draw): x along its east.
    const double azimuth = std::atan2(map[std::size_t(c.id)].y, map[std::size_t(c.id)].x);
    auto map_x = [&](int cam) { return ui::project_to_map(normalize(map[std::size_t(cam)]), azimuth, map_elevation).x; };

    // →: the camera the engine selects shows the front moved left; on the map it lies to the right.
    e.jump_to_camera(c.id);  // false when it is already shown
    EXPECT_TRUE(e.apply(player::Action::camera_right));
    const int r = e.selection().camera;
    EXPECT_EQ(r, n.right);
    EXPECT_LT(front_x(m, c.id, r), 0) << "→ turned the object's front to the right";
    EXPECT_GT(map_x(r), map_x(c.id)) << "mini-map: → went to a camera drawn left of the current one";

    // Drag right, in steps of 2 px of a 900 px window (0.4°), until the snap leaves the camera.
    e.jump_to_camera(c.id);  // false when it is already shown
    ui::DragRotation drag;
    drag.begin(c.position, c.up, c.look_at);
    int s = c.id;
    for (int k = 0; k < 900 && s == c.id; ++k) {
      drag.move(2, 0, 900);
      e.snap_to_direction(drag.direction());
      s = e.selection().camera;
    }
    EXPECT_NE(s, c.id) << "a drag of half a turn never left the camera";
    EXPECT_GT(front_x(m, c.id, s), 0) << "a drag to the right turned the object's front to the left";
    EXPECT_LT(map_x(s), map_x(c.id)) << "mini-map: the drag went to a camera drawn right of the current one";
    ++out.cameras;
  }
  return out;
}

fs::path imported(const std::string& fixture, const fs::path& tmp) {
  const fs::path out = tmp / fixture;
  cinema::ImportOptions o;
  o.threads = 2;
  cinema::import_cinema(kFixtures / fixture, out, o);
  return out;
}

}  // namespace

// The reference: a native database (a latitude-longitude rig as `panoptes run` lays it out, z up).
TEST(CinemaNavigation, NativeDatabaseTurnsTheObjectByTheRules) {
  player::testing::TempDir tmp("cinema_navigation");
  store::Manifest m = player::testing::ring_manifest(1, 1, 48, 40);
  m.cameras.clear();
  m.graph.neighbours.clear();
  const camera::Rig rig = camera::make_rig("latlon:3x8", camera::Domain{{0, 0, 0}, {10, 10, 10}});
  const camera::NavigationGraph g = camera::build_navigation_graph(rig);
  m.rig.kind = "latlon";
  for (int c = 0; c < rig.size(); ++c) {
    const auto& rc = rig.cameras[std::size_t(c)];
    store::CameraEntry e;
    e.id = c;
    e.position = rc.position;
    e.look_at = rc.look_at;
    e.up = rc.up;
    e.fov_y_deg = rc.fov_y_degrees;
    e.labels.lat_deg = rc.latitude_deg;
    e.labels.lon_deg = rc.longitude_deg;
    m.cameras.push_back(e);
    const auto& n = g.neighbours[std::size_t(c)];
    m.graph.neighbours.push_back({n.left, n.right, n.up, n.down, n.in, n.out});
  }
  player::testing::write_stamped(tmp.path / "db", m, 1);
  EXPECT_EQ(check_gestures(tmp.path / "db").cameras, 24);
}

// ParaView's extractor turns over +y and its views past the pole (theta 120, 240) are stored turned.
TEST(CinemaNavigation, ParaViewExtractsTurnLikeANativeDatabase) {
  player::testing::TempDir tmp("cinema_navigation");
  EXPECT_EQ(check_gestures(imported("paraview_extracts.cdb", tmp.path)).cameras, 12);
}

// cinema_python counts phi from -x, clockwise: mirrored against Panoptes' own azimuth.
TEST(CinemaNavigation, CinemaPythonTurnsLikeANativeDatabase) {
  player::testing::TempDir tmp("cinema_navigation");
  EXPECT_EQ(check_gestures(imported("paraview_cinema_python.cdb", tmp.path)).cameras, 12);
}

// Ascent: theta polar from +z; its theta 0 ring is the pole (skipped), 60 and 120 are checked.
TEST(CinemaNavigation, AscentTurnsLikeANativeDatabase) {
  player::testing::TempDir tmp("cinema_navigation");
  EXPECT_EQ(check_gestures(imported("ascent_convention.cdb", tmp.path)).cameras, 8);
}
