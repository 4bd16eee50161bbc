#include "camera/navigation.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <cmath>
#include <string>

#include "camera/angles.hpp"
#include "camera/volume_rigs.hpp"
#include "core/error.hpp"

namespace panoptes::camera {

int Neighbours::operator[](Move m) const {
  switch (m) {
    case Move::right: return right;
    case Move::left: return left;
    case Move::up: return up;
    case Move::down: return down;
    case Move::in: return in;
    case Move::out: return out;
  }
  return -1;
}

Move opposite(Move m) {
  switch (m) {
    case Move::right: return Move::left;
    case Move::left: return Move::right;
    case Move::up: return Move::down;
    case Move::down: return Move::up;
    case Move::in: return Move::out;
    case Move::out: return Move::in;
  }
  return m;
}

int MoveTrail::next(int camera, Move move, int graph_target) {
  if (!steps_.empty() && steps_.back().to != camera) steps_.clear();  // moved by other means
  if (!steps_.empty() && steps_.back().move == opposite(move)) {
    const int back = steps_.back().from;
    steps_.pop_back();
    return back;
  }
  if (graph_target < 0 || graph_target == camera) return graph_target;
  if (int(steps_.size()) == kMaxSteps) steps_.erase(steps_.begin(), steps_.begin() + kMaxSteps / 2);
  if (steps_.capacity() < std::size_t(kMaxSteps)) steps_.reserve(kMaxSteps);
  steps_.push_back({camera, graph_target, move});
  return graph_target;
}

CameraLocator::CameraLocator(const Rig& rig) {
  std::vector<Vec3> positions;
  std::vector<int> shells;
  positions.reserve(rig.cameras.size());
  shells.reserve(rig.cameras.size());
  for (const RigCamera& c : rig.cameras) {
    positions.push_back(c.position);
    shells.push_back(c.shell);
  }
  *this = CameraLocator(positions, shells, rig.center);
}

CameraLocator::CameraLocator(const std::vector<Vec3>& positions, const std::vector<int>& shells, const Vec3& center) {
  if (positions.size() != shells.size())
    throw Error("camera locator: " + std::to_string(positions.size()) + " positions but " +
                std::to_string(shells.size()) + " shell indices; expected one per camera");
  int count = 0;
  for (int s : shells) {
    if (s < 0) throw Error("camera locator: shell index " + std::to_string(s) + "; expected >= 0");
    count = std::max(count, s + 1);
  }
  std::vector<std::vector<Vec3>> dirs(count);
  shells_.resize(count);
  for (std::size_t k = 0; k < positions.size(); ++k) {
    const Vec3 d = positions[k] - center;
    if (!(norm(d) > 0))
      throw Error("camera locator: camera " + std::to_string(k) + " sits at the centre; expected it away from the centre");
    dirs[shells[k]].push_back(d);
    shells_[shells[k]].ids.push_back(int(k));
  }
  for (int s = 0; s < count; ++s) shells_[s].index = SphereIndex(dirs[s]);
}

int CameraLocator::nearest(const Vec3& direction, int shell) const {
  if (shell < 0 || shell >= int(shells_.size())) return -1;
  const int k = shells_[shell].index.nearest(direction);
  return k < 0 ? -1 : shells_[shell].ids[k];
}

namespace {

constexpr int kCandidates = 4;  // per camera and cone, kept for the reversibility matching

struct ConeCandidates {
  std::array<int, kCandidates> id;
  std::array<float, kCandidates> score;
  void clear() {
    id.fill(-1);
    score.fill(std::numeric_limits<float>::infinity());
  }
  void offer(int j, float sc) {
    if (!(sc < score[kCandidates - 1] || (sc == score[kCandidates - 1] && j < id[kCandidates - 1]))) return;
    int k = kCandidates - 1;
    while (k > 0 && (sc < score[k - 1] || (sc == score[k - 1] && j < id[k - 1]))) {
      score[k] = score[k - 1];
      id[k] = id[k - 1];
      --k;
    }
    score[k] = sc;
    id[k] = j;
  }
  // The score of j among the candidates, or infinity.
  float score_of(int j) const {
    for (int k = 0; k < kCandidates; ++k)
      if (id[k] == j) return score[k];
    return std::numeric_limits<float>::infinity();
  }
};

// Pairs opposite moves (right/left, up/down) so that most moves are reversible. An edge i -> j exists
// when j is among i's near-best candidates (score within 1 + tolerance of the best) in cone
// `forward` and i is among j's near-best candidates in the opposite cone. Edges are matched greedily
// by summed score, then short augmenting paths raise the number of matched (reversible) cameras —
// in hexagon-like arrangements (Fibonacci) two candidates are equally good and a greedy choice
// alone leaves many cameras unpaired. Unpaired cameras take their plainly best candidate.
void match_axis(const std::vector<std::array<ConeCandidates, 4>>& cand, int forward, int backward, double tolerance,
                std::vector<int>& fwd, std::vector<int>& bwd) {
  const int n = int(cand.size());
  struct Edge {
    float score;
    int i, j;
  };
  std::vector<Edge> edges;
  auto near_best = [&](const ConeCandidates& c, int k) {
    return c.id[k] >= 0 && c.score[k] <= c.score[0] * (1.0 + tolerance);
  };
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < kCandidates && near_best(cand[i][forward], k); ++k) {
      const int j = cand[i][forward].id[k];
      const ConeCandidates& back = cand[j][backward];
      for (int m = 0; m < kCandidates && near_best(back, m); ++m)
        if (back.id[m] == i) {
          edges.push_back({cand[i][forward].score[k] + back.score[m], i, j});
          break;
        }
    }
  std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
    return a.score != b.score ? a.score < b.score : (a.i != b.i ? a.i < b.i : a.j < b.j);
  });
  fwd.assign(n, -1);
  bwd.assign(n, -1);
  for (const Edge& e : edges)
    if (fwd[e.i] < 0 && bwd[e.j] < 0) {
      fwd[e.i] = e.j;
      bwd[e.j] = e.i;
    }
  // Adjacency (CSR, by score) for augmenting paths.
  std::vector<int> first(n + 1, 0), target(edges.size());
  for (const Edge& e : edges) ++first[e.i + 1];
  for (int i = 0; i < n; ++i) first[i + 1] += first[i];
  {
    std::vector<int> fill(first.begin(), first.end() - 1);
    for (const Edge& e : edges) target[fill[e.i]++] = e.j;
  }
  // Breadth-first search for an augmenting path from each unmatched source, exploring at most
  // kExplore sources so the whole pass stays O(N).
  constexpr int kExplore = 64;
  std::vector<int> seen(n, -1), parent(n, -1), queue;
  queue.reserve(kExplore + 1);
  for (int root = 0; root < n; ++root) {
    if (fwd[root] >= 0 || first[root] == first[root + 1]) continue;
    queue.assign(1, root);
    int free_target = -1;
    for (std::size_t q = 0; q < queue.size() && free_target < 0 && queue.size() <= kExplore; ++q) {
      const int a = queue[q];
      for (int e = first[a]; e < first[a + 1]; ++e) {
        const int b = target[e];
        if (seen[b] == root) continue;
        seen[b] = root;
        parent[b] = a;
        if (bwd[b] < 0) {
          free_target = b;
          break;
        }
        queue.push_back(bwd[b]);
      }
    }
    // Flip the path: each source on it takes the target found through it.
    for (int b = free_target; b >= 0;) {
      const int a = parent[b], previous = fwd[a];
      fwd[a] = b;
      bwd[b] = a;
      b = a == root ? -1 : previous;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (fwd[i] < 0) fwd[i] = cand[i][forward].id[0];
    if (bwd[i] < 0) bwd[i] = cand[i][backward].id[0];
  }
}

}  // namespace

NavigationGraph build_navigation_graph(const Rig& rig, const GraphOptions& options) {
  if (!(options.cone_degrees > 0 && options.cone_degrees <= 90))
    throw Error("navigation graph: cone half-angle " + std::to_string(options.cone_degrees) +
                " degrees; expected 0 < cone <= 90");
  if (!(options.alignment_weight >= 0))
    throw Error("navigation graph: alignment weight " + std::to_string(options.alignment_weight) + "; expected >= 0");
  if (!(options.reversible_tolerance >= 0))
    throw Error("navigation graph: reversible tolerance " + std::to_string(options.reversible_tolerance) +
                "; expected >= 0");
  if (rig.is_lattice()) return build_lattice_graph(rig);
  if (rig.path) return build_path_graph(rig);
  if (rig.spec.rfind("inshell", 0) == 0) return build_shell_interior_graph(rig);
  const int n = rig.size();
  NavigationGraph graph;
  graph.neighbours.resize(n);
  if (n == 0) return graph;
  const CameraLocator locator(rig);
  const double cos_cone = std::cos(options.cone_degrees * kDeg);
  const double reach = 1.0 + options.reversible_tolerance;
  // Each camera's own image plane (up-vector rule and pole fallback included), built serially so a
  // bad camera throws here and not inside the parallel loop.
  std::vector<std::array<Vec3, 2>> basis(n);
  for (int i = 0; i < n; ++i) {
    const RigCamera& rc = rig.cameras[i];
    const Camera cam(rc.position, rc.look_at, rc.up, rc.fov_y_degrees, 1, 1);
    basis[i] = {cam.right(), cam.up()};
  }
  std::vector<std::array<ConeCandidates, 4>> cand(n);
  constexpr double kSame = 1e-9;  // radians: cameras closer than this are the same viewpoint

#pragma omp parallel for schedule(dynamic, 64) if (n >= 4096)  // threads cost more than small rigs
  for (int i = 0; i < n; ++i) {
    const Vec3 u = rig.direction(i);
    const Vec3 axes[4] = {basis[i][0], -basis[i][0], basis[i][1], -basis[i][1]};
    const int shell = rig.cameras[i].shell;
    const SphereIndex& index = locator.shell_index(shell);
    std::array<ConeCandidates, 4>& best = cand[i];
    auto visit = [&](int k, const Vec3& p, double c) {
      const int j = locator.global_id(shell, k);
      if (j == i) return;
      // Initial heading of the great circle from u to p: p's component in the tangent plane at u.
      const Vec3 t = p - u * c;
      const double tn = norm(t);
      const double angle = std::atan2(tn, c);
      if (angle < kSame) return;
      if (tn < 1e-12) {
        // Exactly opposite: every heading leads there, so it is a (last-resort) candidate in all cones.
        for (int a = 0; a < 4; ++a) best[a].offer(j, float(2 * angle));
        return;
      }
      for (int a = 0; a < 4; ++a) {
        const double cos_dev = dot(t, axes[a]) / tn;
        if (cos_dev < cos_cone) continue;
        best[a].offer(j, float(angle * (1.0 + options.alignment_weight * (1.0 - cos_dev))));
      }
    };
    // Grow the cap: once (1 + tolerance) x a cone's best score is within the cap radius, no camera
    // outside can be a candidate (score >= angle).
    for (double r = 2.5 * index.spacing();; r *= 2) {
      for (auto& b : best) b.clear();
      index.for_each_within(u, r, visit);
      bool done = r >= kPi;
      if (!done) {
        done = true;
        for (int a = 0; a < 4; ++a) done = done && best[a].score[0] * reach <= r;
      }
      if (done) break;
    }
    Neighbours& nb = graph.neighbours[i];
    // Shell 0 is the outermost: "in" moves to the next higher shell index.
    nb.in = locator.nearest(u, shell + 1);
    nb.out = shell > 0 ? locator.nearest(u, shell - 1) : -1;
  }
  std::vector<int> fwd, bwd;
  match_axis(cand, 0, 1, options.reversible_tolerance, fwd, bwd);
  for (int i = 0; i < n; ++i) {
    graph.neighbours[i].right = fwd[i];
    graph.neighbours[i].left = bwd[i];
  }
  match_axis(cand, 2, 3, options.reversible_tolerance, fwd, bwd);
  for (int i = 0; i < n; ++i) {
    graph.neighbours[i].up = fwd[i];
    graph.neighbours[i].down = bwd[i];
  }
  return graph;
}

}  // namespace panoptes::camera
