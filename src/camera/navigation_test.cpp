#include "camera/navigation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "camera/angles.hpp"
#include "camera/rig_spec.hpp"
#include "camera/rig_stats.hpp"
#include "core/error.hpp"

using namespace panoptes;
using namespace panoptes::camera;

namespace {
const Domain kDomain{{0, 0, 0}, {256, 512, 160}};

double wrap180(double a) {
  while (a > 180) a -= 360;
  while (a <= -180) a += 360;
  return a;
}

// Presses `move` from `start` until back at start (or max_steps); returns steps and the total signed
// longitude travelled and the largest |latitude| visited.
struct Walk {
  int steps = -1;
  double longitude = 0, max_abs_lat = 0;
};
Walk walk(const Rig& rig, const NavigationGraph& g, int start, Move move, int max_steps) {
  Walk w;
  int c = start;
  for (int s = 1; s <= max_steps; ++s) {
    const int n = g.next(c, move);
    if (n < 0) return w;
    w.longitude += wrap180(rig.cameras[n].longitude_deg - rig.cameras[c].longitude_deg);
    w.max_abs_lat = std::max(w.max_abs_lat, std::abs(rig.cameras[n].latitude_deg));
    c = n;
    if (c == start) {
      w.steps = s;
      return w;
    }
  }
  return w;
}

int equatorial_camera(const Rig& rig) {
  int best = 0;
  for (int c = 0; c < rig.size(); ++c)
    if (std::abs(rig.cameras[c].latitude_deg) < std::abs(rig.cameras[best].latitude_deg)) best = c;
  return best;
}
}  // namespace

TEST(Navigation, BasicInvariantsOnEveryRig) {
  for (const char* spec : {"yinyang", "yinyang:3x7", "yinyang:13x39", "latlon", "latlon:9x15", "fibonacci",
                           "fibonacci:7", "fibonacci:1000", "shells:yinyang@1.5,2.5,4"}) {
    const Rig rig = make_rig(spec, kDomain);
    const NavigationGraph g = build_navigation_graph(rig);
    ASSERT_EQ(g.size(), rig.size());
    for (int c = 0; c < rig.size(); ++c) {
      const Neighbours& nb = g.neighbours[c];
      for (Move m : {Move::right, Move::left, Move::up, Move::down, Move::in, Move::out}) {
        const int j = nb[m];
        EXPECT_NE(j, c) << spec;
        EXPECT_GE(j, -1);
        EXPECT_LT(j, rig.size());
        if (j >= 0 && m != Move::in && m != Move::out) {
          EXPECT_EQ(rig.cameras[j].shell, rig.cameras[c].shell) << spec;
        }
      }
      // Rigs covering the sphere always have all four image-plane moves.
      EXPECT_GE(nb.right, 0) << spec << " camera " << c;
      EXPECT_GE(nb.left, 0) << spec << " camera " << c;
      EXPECT_GE(nb.up, 0) << spec << " camera " << c;
      EXPECT_GE(nb.down, 0) << spec << " camera " << c;
    }
    // Every camera is reachable from every other one.
    const RigStatistics st = rig_statistics(rig, g);
    EXPECT_EQ(st.reachable_from_0, rig.size()) << spec;
    EXPECT_TRUE(st.strongly_connected) << spec;
    for (int start : {rig.size() / 3, rig.size() - 1}) EXPECT_EQ(reachable_count(g, start), rig.size()) << spec;
  }
}

TEST(Navigation, RightLeadsToTheImageRight) {
  const Rig rig = make_rig("yinyang", kDomain);
  const NavigationGraph g = build_navigation_graph(rig);
  for (int c = 0; c < rig.size(); ++c) {
    const Camera cam = rig.camera(c, 100, 100);
    // The right neighbour projects right of the image centre, the up neighbour above it (as seen
    // on the camera's tangent plane: compare displacements with the image basis).
    const Vec3 dr = rig.cameras[g.neighbours[c].right].position - cam.position();
    const Vec3 du = rig.cameras[g.neighbours[c].up].position - cam.position();
    EXPECT_GT(dot(dr, cam.right()), std::abs(dot(dr, cam.up())) * 0.99) << c;
    EXPECT_GT(dot(du, cam.up()), std::abs(dot(du, cam.right())) * 0.99) << c;
  }
}

TEST(Navigation, RightCirclesTheEquatorAndReturns) {
  for (const char* spec : {"yinyang", "yinyang:8x20", "latlon:9x15", "latlon"}) {
    const Rig rig = make_rig(spec, kDomain);
    const NavigationGraph g = build_navigation_graph(rig);
    const int start = equatorial_camera(rig);
    const Walk w = walk(rig, g, start, Move::right, rig.size());
    std::printf("%s: right from camera %d returns after %d steps, %.1f deg of longitude, |lat| <= %.1f\n", spec, start,
                w.steps, w.longitude, w.max_abs_lat);
    ASSERT_GT(w.steps, 3) << spec;
    EXPECT_NEAR(w.longitude, 360, 1e-6) << spec;  // eastwards, exactly once around
    EXPECT_LT(w.max_abs_lat, 30) << spec;
    const Walk back = walk(rig, g, start, Move::left, rig.size());
    EXPECT_EQ(back.steps, w.steps) << spec;
    EXPECT_NEAR(back.longitude, -360, 1e-6) << spec;
  }
  // Fibonacci has no rings: pressing right still travels east around the sphere, drifting in
  // latitude (the spiral's lattice rows are tilted against east-west), so it need not come back.
  const Rig fib = make_rig("fibonacci:500", kDomain);
  const NavigationGraph g = build_navigation_graph(fib);
  int c = equatorial_camera(fib);
  double lon = 0, max_lat = 0;
  for (int s = 0; s < 60 && lon < 360; ++s) {
    const int n = g.next(c, Move::right);
    lon += wrap180(fib.cameras[n].longitude_deg - fib.cameras[c].longitude_deg);
    max_lat = std::max(max_lat, std::abs(fib.cameras[n].latitude_deg));
    c = n;
  }
  std::printf("fibonacci:500: right travels %.1f deg of longitude, |lat| <= %.1f\n", lon, max_lat);
  EXPECT_GE(lon, 360);
  EXPECT_LT(max_lat, 30);
}

TEST(Navigation, RightThenLeftReturnsForMostCameras) {
  struct Case {
    const char* spec;
    double min_fraction;
  };
  for (const Case& c : {Case{"yinyang", 0.88}, Case{"fibonacci", 0.8}, Case{"latlon", 0.95}, Case{"yinyang:13x39", 0.93},
                        Case{"fibonacci:1000", 0.93}, Case{"latlon:22x45+poles", 0.95}}) {
    const Rig rig = make_rig(c.spec, kDomain);
    const NavigationGraph g = build_navigation_graph(rig);
    const RigStatistics st = rig_statistics(rig, g);
    std::printf("%-20s %5d cameras: right-then-left returns %.3f, up-then-down %.3f\n", c.spec, rig.size(),
                st.right_left_return, st.up_down_return);
    EXPECT_GE(st.right_left_return, c.min_fraction) << c.spec;
    EXPECT_GE(st.up_down_return, 0.8) << c.spec;
  }
}

// Issue 34: on the shipped sphere rigs, a move then the opposite move — and the move twice then the
// opposite twice — come back for >= 95 % of cameras as the players press them (MoveTrail). The graph
// alone cannot reach it (docs/cameras.md): its own figures stay checked above and here.
TEST(Navigation, MovesUndoThemselvesInThePlayersOnEveryShippedSphereRig) {
  for (const char* spec : {"yinyang", "latlon", "fibonacci", "yinyang:13x39", "latlon:22x45+poles", "fibonacci:1000",
                           "shells:yinyang@1.5,2.5,4"}) {
    for (UpAxis axis : {UpAxis::z_up, UpAxis::z_down}) {
      RigSpec rs = RigSpec::parse(spec);
      rs.up_axis = axis;
      const Rig rig = make_rig(rs, kDomain);
      const NavigationGraph g = build_navigation_graph(rig);
      const RigStatistics st = rig_statistics(rig, g);
      std::printf("%-26s %-6s graph alone: right-left %.3f left-right %.3f up-down %.3f down-up %.3f; "
                  "players: %.3f %.3f %.3f %.3f\n",
                  spec, std::string(to_string(axis)).c_str(), st.right_left_return, st.left_right_return, st.up_down_return,
                  st.down_up_return, st.right_left_undo, st.left_right_undo, st.up_down_undo, st.down_up_undo);
      for (double f : {st.right_left_undo, st.left_right_undo, st.up_down_undo, st.down_up_undo}) EXPECT_GE(f, 0.95) << spec;
      EXPECT_GE(st.left_right_return, 0.8) << spec;
      EXPECT_GE(st.down_up_return, 0.8) << spec;
    }
  }
}

TEST(Navigation, MoveTrailRetracesAndForgets) {
  MoveTrail t;
  EXPECT_EQ(t.next(0, Move::up, 5), 5);
  EXPECT_EQ(t.next(5, Move::up, 7), 7);
  EXPECT_EQ(t.previous(7), 5);
  EXPECT_EQ(t.previous(5), -1);
  EXPECT_EQ(t.next(7, Move::down, 9), 5) << "retrace, not the graph's 9";
  EXPECT_EQ(t.next(5, Move::down, 9), 0);
  EXPECT_EQ(t.size(), 0);
  EXPECT_EQ(t.next(0, Move::down, -1), -1) << "no move: nothing recorded";
  EXPECT_EQ(t.size(), 0);
  EXPECT_EQ(t.next(0, Move::right, 1), 1);
  EXPECT_EQ(t.next(1, Move::up, 2), 2);
  EXPECT_EQ(t.next(2, Move::left, 3), 3) << "not the opposite of the last move: the graph";
  EXPECT_EQ(t.next(8, Move::left, 4), 4) << "moved elsewhere by other means: the trail restarts";
  EXPECT_EQ(t.size(), 1);
  EXPECT_EQ(t.next(4, Move::right, 6), 8);
  EXPECT_EQ(t.next(1, Move::in, 11), 11);
  EXPECT_EQ(t.next(11, Move::out, 12), 1);
  // Long walks keep the recent half when the trail is full, and never grow beyond kMaxSteps.
  t.clear();
  int c = 0;
  for (int k = 0; k < 3 * MoveTrail::kMaxSteps; ++k) c = t.next(c, Move::right, c + 1);
  EXPECT_LE(t.size(), MoveTrail::kMaxSteps);
  EXPECT_EQ(t.next(c, Move::left, -1), c - 1);
}

TEST(Navigation, InOutBetweenShells) {
  const Rig rig = make_rig("shells:fibonacci:200@1.5,2.5,4", kDomain);
  const NavigationGraph g = build_navigation_graph(rig);
  for (int c = 0; c < rig.size(); ++c) {
    const int shell = c / 200, k = c % 200;
    EXPECT_EQ(g.next(c, Move::in), shell < 2 ? (shell + 1) * 200 + k : -1);
    EXPECT_EQ(g.next(c, Move::out), shell > 0 ? (shell - 1) * 200 + k : -1);
    // Image-plane moves stay on the shell and mirror the outermost shell's graph.
    EXPECT_EQ(g.next(c, Move::right) % 200, g.next(k, Move::right));
  }
  const Rig single = make_rig("yinyang", kDomain);
  for (const Neighbours& nb : build_navigation_graph(single).neighbours) {
    EXPECT_EQ(nb.in, -1);
    EXPECT_EQ(nb.out, -1);
  }
}

TEST(Navigation, FileRigWithDifferentPatternsPerShell) {
  // Two shells with different cameras: in/out snap to the nearest direction on the next shell.
  Rig rig = make_rig("fibonacci:50@4", kDomain);
  const Rig inner = make_rig("yinyang:3x7@2", kDomain);
  for (RigCamera c : inner.cameras) {
    c.shell = 1;
    rig.cameras.push_back(c);
  }
  rig.shell_count = 2;
  const NavigationGraph g = build_navigation_graph(rig);
  for (int c = 0; c < 50; ++c) {
    const int in = g.next(c, Move::in);
    ASSERT_GE(in, 50);
    double best = 10;
    for (int j = 50; j < rig.size(); ++j) best = std::min(best, angle_between(rig.direction(c), rig.direction(j)));
    EXPECT_NEAR(angle_between(rig.direction(c), rig.direction(in)), best, 1e-12);
  }
  for (int c = 50; c < rig.size(); ++c) EXPECT_LT(g.next(c, Move::out), 50);
}

TEST(Navigation, RejectsBadOptions) {
  const Rig rig = make_rig("fibonacci:10", kDomain);
  GraphOptions o;
  o.cone_degrees = 0;
  EXPECT_THROW(build_navigation_graph(rig, o), Error);
  o = {};
  o.alignment_weight = -1;
  EXPECT_THROW(build_navigation_graph(rig, o), Error);
}

TEST(Navigation, TinyRigs) {
  // Two antipodal cameras (Yin-Yang 1x1): every heading leads to the other one.
  const Rig two = make_rig("yinyang:1x1", kDomain);
  ASSERT_EQ(two.size(), 2);
  const NavigationGraph g2 = build_navigation_graph(two);
  for (Move m : {Move::right, Move::left, Move::up, Move::down}) {
    EXPECT_EQ(g2.next(0, m), 1);
    EXPECT_EQ(g2.next(1, m), 0);
  }
  // A lone camera has no neighbours and the whole sphere but one point is uncovered.
  const Rig one = make_rig("fibonacci:1", kDomain);
  const NavigationGraph g1 = build_navigation_graph(one);
  EXPECT_EQ(g1.neighbours[0], Neighbours{});
  const RigStatistics st = rig_statistics(one, g1);
  EXPECT_NEAR(st.covering_deg, 180, 1e-9);
  EXPECT_EQ(st.reachable_from_0, 1);
}
