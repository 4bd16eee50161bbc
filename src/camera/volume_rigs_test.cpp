#include "camera/volume_rigs.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "camera/rig_spec.hpp"
#include "core/error.hpp"

using namespace panoptes;
using namespace panoptes::camera;

namespace {
const Domain kVolumeDomain{{10, -5, 0}, {400, 300, 160}};

// The world axis index and sign of the move that goes +x / +y / +z.
Move move_along(UpAxis up, int axis) {
  Vec3 d{0, 0, 0};
  d[axis] = 1;
  return lattice_move_towards(d, up);
}
}  // namespace

TEST(LatticeRig, NodesAtCellCentresLookingNorthWithTheSkyUp) {
  RigSpec spec = RigSpec::parse("lattice:4x4x3");
  const Rig rig = make_rig(spec, kVolumeDomain);
  ASSERT_EQ(rig.size(), 48);
  EXPECT_EQ(rig.lattice, (std::array<int, 3>{4, 4, 3}));
  EXPECT_EQ(rig.spec, "lattice:4x4x3@0");
  // Node (1, 2, 0): x = 10 + 400·1.5/4, y = −5 + 300·2.5/4, z = 160·0.5/3.
  const RigCamera& c = rig.cameras[std::size_t(lattice_id(rig.lattice, 1, 2, 0))];
  EXPECT_NEAR(c.position.x, 160, 1e-9);
  EXPECT_NEAR(c.position.y, 182.5, 1e-9);
  EXPECT_NEAR(c.position.z, 160.0 / 6, 1e-9);
  const Camera cam = rig.camera(0, 64, 64);
  EXPECT_NEAR(cam.forward().y, 1, 1e-12);  // north = +y for z_up
  EXPECT_NEAR(cam.up().z, 1, 1e-12);
  EXPECT_EQ(c.fov_y_degrees, kInsideFovDegrees);
  EXPECT_EQ(c.patch, "lattice");
  // A margin shrinks the box: node 0 of a 1-node axis stays at the centre, the outer nodes move inwards.
  const Rig m = make_rig("lattice:2x1x1@0.25", kVolumeDomain);
  EXPECT_NEAR(m.cameras[0].position.x, 10 + 400 * (0.25 + 0.5 * 0.25), 1e-9);
  EXPECT_NEAR(m.cameras[0].position.y, -5 + 150, 1e-9);
}

TEST(LatticeRig, WalkingForwardAlongEveryWorldAxisReachesTheNeighbour) {
  for (UpAxis up : {UpAxis::z_up, UpAxis::z_down}) {
    RigSpec spec = RigSpec::parse("lattice:4x3x2");
    spec.up_axis = up;
    const Rig rig = make_rig(spec, kVolumeDomain);
    const NavigationGraph g = build_navigation_graph(rig);
    ASSERT_EQ(g.size(), rig.size());
    const std::array<int, 3> n = rig.lattice;
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          const int c = lattice_id(n, i, j, k);
          const int idx[3] = {i, j, k};
          for (int a = 0; a < 3; ++a) {
            int plus[3] = {i, j, k}, minus[3] = {i, j, k};
            ++plus[a], --minus[a];
            const int want_plus = idx[a] + 1 < n[a] ? lattice_id(n, plus[0], plus[1], plus[2]) : -1;
            const int want_minus = idx[a] > 0 ? lattice_id(n, minus[0], minus[1], minus[2]) : -1;
            Vec3 d{0, 0, 0};
            d[a] = 1;
            EXPECT_EQ(g.next(c, lattice_move_towards(d, up)), want_plus) << "camera " << c << " axis " << a;
            EXPECT_EQ(g.next(c, lattice_move_towards(-d, up)), want_minus) << "camera " << c << " axis " << a;
            if (want_plus >= 0) {
              // The move lands exactly one lattice step further along +axis.
              const Vec3 step = rig.cameras[std::size_t(want_plus)].position - rig.cameras[std::size_t(c)].position;
              EXPECT_GT(step[a], 0);
              EXPECT_NEAR(step[(a + 1) % 3], 0, 1e-9);
              EXPECT_NEAR(step[(a + 2) % 3], 0, 1e-9);
            }
          }
        }
  }
  // The domain's up: with z as depth, "up" goes to smaller z.
  EXPECT_EQ(move_along(UpAxis::z_down, 2), Move::down);
  EXPECT_EQ(move_along(UpAxis::z_up, 2), Move::up);
  EXPECT_EQ(move_along(UpAxis::z_up, 1), Move::in);  // north = forward
  EXPECT_EQ(move_along(UpAxis::z_down, 0), Move::in);
}

TEST(LatticeRig, SpecErrorsNameTheText) {
  for (const char* bad : {"lattice:4x4", "lattice:0x2x2", "lattice:2x2x2@0.5", "lattice:2x2x2@x", "latticex",
                          "lattice:100000x100000x100000"}) {
    try {
      RigSpec::parse(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(RigSpec::parse(RigSpec::parse("lattice:2x3x4@0.125").to_string()).to_string(), "lattice:2x3x4@0.125");
  EXPECT_EQ(RigSpec::parse("lattice").cameras_per_shell(), 48);
}

TEST(PathRig, CamerasLookAlongThePathAndWalkInOut) {
  const auto file = std::filesystem::temp_directory_path() / "panoptes_path_rig_test.txt";
  {
    std::ofstream(file) << "# a flight\n100 100 80\n200, 100, 80\n\n200 200 40  # turn\n";
  }
  const Rig rig = make_rig("path:" + file.string(), kVolumeDomain);
  ASSERT_EQ(rig.size(), 3);
  EXPECT_TRUE(rig.path);
  EXPECT_NEAR(rig.camera(0, 8, 8).forward().x, 1, 1e-12);
  EXPECT_NEAR(rig.camera(2, 8, 8).forward().y, 0.9284766908852593, 1e-9);  // keeps the last leg's direction
  const NavigationGraph g = build_navigation_graph(rig);
  EXPECT_EQ(g.next(0, Move::in), 1);
  EXPECT_EQ(g.next(1, Move::in), 2);
  EXPECT_EQ(g.next(2, Move::in), -1);
  EXPECT_EQ(g.next(2, Move::out), 1);
  EXPECT_EQ(g.next(0, Move::out), -1);
  {
    std::ofstream(file) << "1 2 3\n1 2 3\n";
  }
  try {
    make_rig("path:" + file.string(), kVolumeDomain);
    ADD_FAILURE();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  {
    std::ofstream(file) << "1 2\n";
  }
  EXPECT_THROW(make_rig("path:" + file.string(), kVolumeDomain), FileError);
  std::filesystem::remove(file);
}

// Issue 33: rings inside a spherical shell. Every camera sits between the inner and the outer radius,
// its image's up (after the Camera's orthogonalization) is the local radial direction and it looks
// along its ring, for both up axes; the spec round-trips and refuses radii outside the shell.
TEST(ShellInteriorRig, CamerasBetweenTheRadiiWithTheRadialDirectionUp) {
  const Domain shell{{-1, -1, -1}, {2, 2, 2}};  // a shell grid's bounding box: outer radius 1
  for (UpAxis up_axis : {UpAxis::z_up, UpAxis::z_down}) {
    RigSpec spec = RigSpec::parse("inshell:3x8@0.5,0.8");
    spec.up_axis = up_axis;
    const Rig rig = make_rig(spec, shell);
    ASSERT_EQ(rig.size(), 2 * 3 * 8);
    EXPECT_EQ(rig.shell_count, 2);
    EXPECT_EQ(rig.spec, "inshell:3x8@0.5,0.8");  // as given; shell 0 is still the largest radius (below)
    for (int id = 0; id < rig.size(); ++id) {
      const RigCamera& rc = rig.cameras[std::size_t(id)];
      const Vec3 radial = normalize(rc.position - rig.center);
      EXPECT_NEAR(norm(rc.position - rig.center), rc.shell == 0 ? 0.8 : 0.5, 1e-12) << id;
      EXPECT_EQ(rc.patch, "inshell");
      const Camera cam = rig.camera(id, 64, 32, Projection::equirectangular);
      // Up is exactly radial, and the view is tangential (perpendicular to it).
      EXPECT_NEAR(dot(cam.up(), radial), 1.0, 1e-9) << "camera " << id;
      EXPECT_NEAR(dot(cam.forward(), radial), 0.0, 1e-9) << "camera " << id;
      // Along the ring: the forward direction has no component along the sky axis.
      const Vec3 sky = SkyFrame::of(up_axis).sky;
      EXPECT_NEAR(dot(cam.forward(), sky), 0.0, 1e-9) << "camera " << id;
    }
    // Cameras on the southern rings have their up pointing away from the sky: radial, not the sky.
    const RigCamera& south = rig.cameras[std::size_t(2 * 8)];  // shell 0, last ring
    EXPECT_LT(dot(normalize(south.position - rig.center), SkyFrame::of(up_axis).sky), -0.5);
    EXPECT_LT(dot(rig.camera(2 * 8, 64, 64).up(), SkyFrame::of(up_axis).sky), -0.5);
  }
}

TEST(ShellInteriorRig, DefaultsAndErrors) {
  const RigSpec d = RigSpec::parse("inshell");
  EXPECT_EQ(d.kind, RigSpec::Kind::inshell);
  EXPECT_EQ(d.rows, 4);
  EXPECT_EQ(d.columns, 12);
  ASSERT_EQ(d.radii.size(), 1u);
  EXPECT_DOUBLE_EQ(d.radii[0], kDefaultInShellRadius);
  EXPECT_EQ(RigSpec::parse(d.to_string()).to_string(), d.to_string());
  EXPECT_EQ(d.cameras_per_shell(), 48);
  const Rig rig = make_rig(d, Domain{{0, 0, 0}, {4, 6, 8}});  // inscribed radius 2 (half the smallest extent)
  EXPECT_NEAR(rig.cameras[0].radius, 2 * kDefaultInShellRadius, 1e-12);
  EXPECT_THROW(RigSpec::parse("inshell:3x8@1.5"), Error);
  EXPECT_THROW(RigSpec::parse("inshell:0x8"), Error);
  EXPECT_THROW(RigSpec::parse("shells:inshell@0.5"), Error);
  try {
    RigSpec::parse("inshell:3x8@1.5");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("inshell radius 1.5 is outside the shell"), std::string::npos) << e.what();
  }
}

// The inshell graph: forward walks along the ring (the way each camera looks), right/left to the ring
// on the image's right/left, up/down between shells; every move reverses and every camera is reachable.
TEST(ShellInteriorRig, GraphWalksAlongRingsAcrossRingsAndBetweenShells) {
  const Domain shell{{-1, -1, -1}, {2, 2, 2}};
  for (UpAxis up_axis : {UpAxis::z_up, UpAxis::z_down}) {
    RigSpec spec = RigSpec::parse("inshell:3x8@0.5,0.8");
    spec.up_axis = up_axis;
    const Rig rig = make_rig(spec, shell);
    const NavigationGraph g = build_navigation_graph(rig);
    ASSERT_EQ(g.neighbours.size(), std::size_t(rig.size()));
    for (int id = 0; id < rig.size(); ++id) {
      const Neighbours& n = g.neighbours[std::size_t(id)];
      const Camera cam = rig.camera(id, 64, 64);
      const Vec3 p = rig.cameras[std::size_t(id)].position;
      ASSERT_GE(n.in, 0);
      EXPECT_GT(dot(rig.cameras[std::size_t(n.in)].position - p, cam.forward()), 0) << id;
      EXPECT_EQ(g.neighbours[std::size_t(n.in)].out, id);
      for (auto [a, b] : {std::pair{n.right, Move::left}, std::pair{n.left, Move::right}, std::pair{n.up, Move::down},
                          std::pair{n.down, Move::up}})
        if (a >= 0) { EXPECT_EQ(g.neighbours[std::size_t(a)][b], id) << id; }
      if (n.right >= 0) { EXPECT_GT(dot(rig.cameras[std::size_t(n.right)].position - p, cam.right()), 0) << id; }
      if (n.left >= 0) { EXPECT_LT(dot(rig.cameras[std::size_t(n.left)].position - p, cam.right()), 0) << id; }
      if (n.up >= 0) { EXPECT_GT(norm(rig.cameras[std::size_t(n.up)].position - rig.center), norm(p - rig.center)) << id; }
    }
    // Everything reachable from camera 0.
    std::vector<int> seen(std::size_t(rig.size()), 0), stack{0};
    seen[0] = 1;
    while (!stack.empty()) {
      const Neighbours n = g.neighbours[std::size_t(stack.back())];
      stack.pop_back();
      for (int next : {n.right, n.left, n.up, n.down, n.in, n.out})
        if (next >= 0 && !seen[std::size_t(next)]) seen[std::size_t(next)] = 1, stack.push_back(next);
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), rig.size());
  }
}
