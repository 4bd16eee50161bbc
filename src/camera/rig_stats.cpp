#include "camera/rig_stats.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "camera/angles.hpp"

namespace panoptes::camera {

namespace {

// Angle from u to its nearest point other than `self` (π if none), by a growing cap.
double nearest_other(const SphereIndex& index, const Vec3& u, int self) {
  for (double r = 2 * index.spacing();; r *= 2) {
    double best = -2;
    index.for_each_within(u, r, [&](int id, const Vec3&, double c) {
      if (id != self && c > best) best = c;
    });
    if (best > -2) {
      const double a = std::acos(std::clamp(best, -1.0, 1.0));
      if (a <= r || r >= kPi) return a;
    }
    if (r >= kPi) return kPi;
  }
}

// The three points nearest to u (ids; -1 where fewer exist).
std::array<int, 3> three_nearest(const SphereIndex& index, const Vec3& u) {
  for (double r = 2 * index.spacing();; r *= 2) {
    std::array<int, 3> id{-1, -1, -1};
    std::array<double, 3> cs{-3, -3, -3};
    index.for_each_within(u, r, [&](int k, const Vec3&, double c) {
      for (int s = 0; s < 3; ++s)
        if (c > cs[s]) {
          for (int t = 2; t > s; --t) {
            cs[t] = cs[t - 1];
            id[t] = id[t - 1];
          }
          cs[s] = c;
          id[s] = k;
          break;
        }
    });
    if (id[2] >= 0 || r >= kPi) return id;
  }
}

}  // namespace

std::vector<double> nearest_neighbour_angles(const SphereIndex& index) {
  std::vector<double> out(index.size());
  for (int k = 0; k < index.size(); ++k) out[k] = nearest_other(index, index.direction(k), k);
  return out;
}

double covering_radius(const SphereIndex& index, int samples) {
  const int n = index.size();
  if (n <= 1) return kPi;  // the antipode of a lone point
  if (samples <= 0) samples = int(std::clamp(100LL * n, 20000LL, 2000000LL));
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  std::vector<std::pair<double, int>> dist(samples);
  auto sample = [&](int k) {
    const double z = 1.0 - (2.0 * k + 1.0) / samples, r = std::sqrt(std::max(0.0, 1 - z * z));
    return Vec3{r * std::cos(golden_angle * k), r * std::sin(golden_angle * k), z};
  };
  for (int k = 0; k < samples; ++k) {
    const Vec3 u = sample(k);
    dist[k] = {angle_between(u, index.direction(index.nearest(u))), k};
  }
  const int top = std::min(samples, 64 + n / 4);
  std::nth_element(dist.begin(), dist.begin() + (top - 1), dist.end(), std::greater<>());
  double best = 0;
  for (int k = 0; k < top; ++k) best = std::max(best, dist[k].first);
  if (n < 3) return best;
  for (int k = 0; k < top; ++k) {
    const Vec3 u = sample(dist[k].second);
    const auto t = three_nearest(index, u);
    const Vec3 a = index.direction(t[0]), b = index.direction(t[1]), c = index.direction(t[2]);
    Vec3 v = cross(b - a, c - a);
    if (!(norm(v) > 1e-15)) continue;
    v = normalize(v);
    if (dot(v, u) < 0) v = -v;
    const double radius = angle_between(v, a);
    // A Voronoi vertex only if no point is closer than the three that define it.
    const double nearest = angle_between(v, index.direction(index.nearest(v)));
    if (nearest >= radius - 1e-12) best = std::max(best, radius);
  }
  return best;
}

int reachable_count(const NavigationGraph& graph, int start) {
  const int n = graph.size();
  if (start < 0 || start >= n) return 0;
  std::vector<char> seen(n, 0);
  std::vector<int> queue{start};
  seen[start] = 1;
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const Neighbours& nb = graph.neighbours[queue[q]];
    for (int j : {nb.right, nb.left, nb.up, nb.down, nb.in, nb.out})
      if (j >= 0 && !seen[j]) {
        seen[j] = 1;
        queue.push_back(j);
      }
  }
  return int(queue.size());
}

namespace {
// Strongly connected iff camera 0 reaches everyone and everyone reaches camera 0 (reverse graph).
bool is_strongly_connected(const NavigationGraph& graph, int reachable_from_0) {
  if (reachable_from_0 != graph.size()) return false;
  std::vector<std::vector<int>> in_edges(std::size_t(graph.size()));
  for (int c = 0; c < graph.size(); ++c) {
    const Neighbours& nb = graph.neighbours[std::size_t(c)];
    for (int j : {nb.right, nb.left, nb.up, nb.down, nb.in, nb.out})
      if (j >= 0) in_edges[std::size_t(j)].push_back(c);
  }
  std::vector<char> seen(std::size_t(graph.size()), 0);
  std::vector<int> queue{0};
  seen[0] = 1;
  for (std::size_t q = 0; q < queue.size(); ++q)
    for (int j : in_edges[std::size_t(queue[q])])
      if (!seen[std::size_t(j)]) {
        seen[std::size_t(j)] = 1;
        queue.push_back(j);
      }
  return int(queue.size()) == graph.size();
}
}  // namespace

RigStatistics rig_statistics(const Rig& rig, const NavigationGraph& graph) {
  RigStatistics st;
  st.cameras = rig.size();
  st.shells = rig.shell_count;
  if (rig.size() == 0) return st;
  const CameraLocator locator(rig);
  st.min_nearest_deg = 180;
  for (int s = 0; s < locator.shell_count(); ++s) {
    const SphereIndex& index = locator.shell_index(s);
    if (index.size() == 0) continue;
    for (double a : nearest_neighbour_angles(index)) {
      st.min_nearest_deg = std::min(st.min_nearest_deg, a / kDeg);
      st.max_nearest_deg = std::max(st.max_nearest_deg, a / kDeg);
    }
    st.covering_deg = std::max(st.covering_deg, covering_radius(index) / kDeg);
  }
  const Move moves[4] = {Move::right, Move::left, Move::up, Move::down};
  int graph_returns[4] = {0, 0, 0, 0}, undo_returns[4] = {0, 0, 0, 0}, missing = 0;
  MoveTrail trail;
  for (int c = 0; c < graph.size(); ++c) {
    const Neighbours& nb = graph.neighbours[c];
    missing += (nb.right < 0) + (nb.left < 0) + (nb.up < 0) + (nb.down < 0);
    for (int k = 0; k < 4; ++k) {
      const Move m = moves[k], back = opposite(m);
      const int j = nb[m];
      if (j >= 0 && graph.next(j, back) == c) ++graph_returns[k];
      // As a player presses the keys: once there and back, then twice there and twice back.
      auto press = [&](int from, Move move) { return from < 0 ? -1 : trail.next(from, move, graph.next(from, move)); };
      trail.clear();
      const int once = press(press(c, m), back);
      trail.clear();
      const int twice = press(press(press(press(c, m), m), back), back);
      if (j >= 0 && once == c && twice == c) ++undo_returns[k];
    }
  }
  const double n = graph.size();
  st.right_left_return = graph_returns[0] / n;
  st.left_right_return = graph_returns[1] / n;
  st.up_down_return = graph_returns[2] / n;
  st.down_up_return = graph_returns[3] / n;
  st.right_left_undo = undo_returns[0] / n;
  st.left_right_undo = undo_returns[1] / n;
  st.up_down_undo = undo_returns[2] / n;
  st.down_up_undo = undo_returns[3] / n;
  st.missing_moves = double(missing) / (4.0 * graph.size());
  st.reachable_from_0 = reachable_count(graph, 0);
  st.strongly_connected = is_strongly_connected(graph, st.reachable_from_0);
  return st;
}

VolumeRigStatistics volume_rig_statistics(const Rig& rig, const NavigationGraph& graph) {
  VolumeRigStatistics st;
  st.cameras = rig.size();
  st.lattice = rig.lattice;
  if (rig.size() == 0) return st;
  const auto pos = [&](int id) { return rig.cameras[std::size_t(id)].position; };
  st.box_lo = st.box_hi = pos(0);
  for (const RigCamera& c : rig.cameras)
    for (int a = 0; a < 3; ++a) {
      st.box_lo[a] = std::min(st.box_lo[a], c.position[a]);
      st.box_hi[a] = std::max(st.box_hi[a], c.position[a]);
    }
  if (rig.is_lattice()) {
    const int strides[3] = {1, rig.lattice[0], rig.lattice[0] * rig.lattice[1]};
    for (int a = 0; a < 3; ++a)
      if (rig.lattice[std::size_t(a)] > 1 && strides[a] < rig.size()) st.spacing[a] = norm(pos(strides[a]) - pos(0));
  }
  st.min_step = 1e300;
  int existing = 0, returned = 0, missing = 0;
  for (int c = 0; c < graph.size(); ++c) {
    const Neighbours& nb = graph.neighbours[std::size_t(c)];
    const std::pair<int, int> moves[] = {{nb.right, 0}, {nb.left, 1}, {nb.up, 2}, {nb.down, 3}, {nb.in, 4}, {nb.out, 5}};
    for (const auto& [j, slot] : moves) {
      if (j < 0) {
        ++missing;
        continue;
      }
      ++existing;
      const double d = norm(pos(j) - pos(c));
      st.min_step = std::min(st.min_step, d);
      st.max_step = std::max(st.max_step, d);
      const Neighbours& back = graph.neighbours[std::size_t(j)];
      const int opposite[] = {back.left, back.right, back.down, back.up, back.out, back.in};
      returned += opposite[slot] == c;
    }
  }
  if (existing == 0) st.min_step = 0;
  st.reverse_return = existing ? double(returned) / existing : 0;
  st.missing_moves = double(missing) / (6.0 * graph.size());
  if (rig.path) {
    std::vector<char> seen(std::size_t(graph.size()), 0);
    for (int c = 0; c >= 0 && c < graph.size() && !seen[std::size_t(c)];) {
      seen[std::size_t(c)] = 1;
      const int next = graph.neighbours[std::size_t(c)].in;
      if (next >= 0) st.path_length += norm(pos(next) - pos(c));
      c = next;
    }
  }
  st.reachable_from_0 = reachable_count(graph, 0);
  st.strongly_connected = is_strongly_connected(graph, st.reachable_from_0);
  return st;
}

}  // namespace panoptes::camera
