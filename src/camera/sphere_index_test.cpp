#include "camera/sphere_index.hpp"

#include <gtest/gtest.h>

#include <random>

#include "camera/navigation.hpp"
#include "camera/rig.hpp"
#include "camera/rig_spec.hpp"
#include "core/error.hpp"

using namespace panoptes;
using namespace panoptes::camera;

namespace {
Vec3 random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return normalize(Vec3{g(rng), g(rng), g(rng)});
}

int brute_nearest(const std::vector<Vec3>& pts, const Vec3& u) {
  int best = -1;
  double best_c = -2;
  for (int k = 0; k < int(pts.size()); ++k) {
    const double c = dot(normalize(pts[k]), u);
    if (c > best_c) {
      best_c = c;
      best = k;
    }
  }
  return best;
}
}  // namespace

TEST(SphereIndex, NearestMatchesBruteForce) {
  std::mt19937_64 rng(42);
  std::vector<std::vector<Vec3>> sets;
  for (int n : {1, 2, 5, 130, 3000}) {
    std::vector<Vec3> s;
    for (int k = 0; k < n; ++k) s.push_back(random_direction(rng) * (1 + k % 3));  // not unit on purpose
    sets.push_back(s);
  }
  // Structured sets with points exactly on the poles, the date line and bucket borders.
  for (auto pattern : {latlon_pattern(9, 18, true), yinyang_pattern(5, 13), fibonacci_pattern(2000)}) {
    std::vector<Vec3> s;
    for (const auto& p : pattern) s.push_back(p.direction);
    sets.push_back(s);
  }
  for (const auto& pts : sets) {
    const SphereIndex index(pts);
    ASSERT_EQ(index.size(), int(pts.size()));
    std::vector<Vec3> queries;
    for (int q = 0; q < 500; ++q) queries.push_back(random_direction(rng));
    for (const Vec3& p : pts) queries.push_back(normalize(p));  // exact hits
    queries.push_back({0, 0, 1});
    queries.push_back({0, 0, -1});
    queries.push_back({-1, 0, 0});
    queries.push_back({-1, -1e-17, 0});
    for (const Vec3& u : queries) {
      const int got = index.nearest(u), want = brute_nearest(pts, u);
      ASSERT_GE(got, 0);
      // Equal angles are legitimate ties.
      EXPECT_NEAR(angle_between(u, pts[got]), angle_between(u, pts[want]), 1e-12) << pts.size();
    }
  }
}

TEST(SphereIndex, WithinVisitsExactlyThePointsInTheCap) {
  std::mt19937_64 rng(7);
  std::vector<Vec3> pts;
  for (int k = 0; k < 2000; ++k) pts.push_back(random_direction(rng));
  const SphereIndex index(pts);
  for (double radius : {0.01, 0.1, 0.5, 1.5, 3.0, 3.2}) {
    for (int q = 0; q < 50; ++q) {
      const Vec3 u = q == 0 ? Vec3{0, 0, 1} : random_direction(rng);
      std::vector<char> seen(pts.size(), 0);
      index.for_each_within(u, radius, [&](int id, const Vec3& p, double c) {
        EXPECT_FALSE(seen[id]);
        seen[id] = 1;
        EXPECT_NEAR(c, dot(p, u), 1e-15);
      });
      for (int k = 0; k < int(pts.size()); ++k) {
        const double a = angle_between(u, pts[k]);
        if (a < radius - 1e-12) {
          EXPECT_TRUE(seen[k]) << radius << " " << a;
        }
        if (a > radius + 1e-12) {
          EXPECT_FALSE(seen[k]) << radius << " " << a;
        }
      }
    }
  }
}

TEST(SphereIndex, EmptyAndBadInput) {
  const SphereIndex empty(std::vector<Vec3>{});
  EXPECT_EQ(empty.nearest({1, 0, 0}), -1);
  EXPECT_THROW(SphereIndex(std::vector<Vec3>{{1, 0, 0}, {0, 0, 0}}), Error);
  const SphereIndex one(std::vector<Vec3>{{0, 2, 0}});
  EXPECT_EQ(one.nearest({0, -1, 0}), 0);
  EXPECT_EQ(one.nearest({0, 0, 0}), -1);
}

TEST(CameraLocator, NearestPerShellMatchesBruteForce) {
  const Rig rig = make_rig("shells:fibonacci:700@2,3", Domain{{0, 0, 0}, {4, 2, 1}});
  const CameraLocator loc(rig);
  ASSERT_EQ(loc.shell_count(), 2);
  std::mt19937_64 rng(3);
  for (int q = 0; q < 300; ++q) {
    const Vec3 u = random_direction(rng);
    for (int shell = 0; shell < 2; ++shell) {
      const int got = loc.nearest(u, shell);
      ASSERT_GE(got, 0);
      EXPECT_EQ(rig.cameras[got].shell, shell);
      double best = 10;
      for (int c = 0; c < rig.size(); ++c)
        if (rig.cameras[c].shell == shell) best = std::min(best, angle_between(u, rig.direction(c)));
      EXPECT_NEAR(angle_between(u, rig.direction(got)), best, 1e-12);
    }
  }
  EXPECT_EQ(loc.nearest({1, 0, 0}, 2), -1);
  EXPECT_THROW(CameraLocator({{1, 0, 0}}, {0, 1}, {0, 0, 0}), Error);
  EXPECT_THROW(CameraLocator({{1, 0, 0}}, {-1}, {0, 0, 0}), Error);
  EXPECT_THROW(CameraLocator({{1, 0, 0}}, {0}, {1, 0, 0}), Error);
}
