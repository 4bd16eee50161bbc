#include "store/manifest_diff.hpp"

#include <algorithm>
#include <cmath>

namespace panoptes::store {

namespace {

using json = nlohmann::json;

std::string shorten(const json& j) {
  std::string s = j.dump();
  return s.size() > 160 ? s.substr(0, 157) + "..." : s;
}

// "X differs (A in the database, B in this run)".
std::string differs(const std::string& what, const json& a, const json& b) {
  return what + " differs (" + shorten(a) + " in the database, " + shorten(b) + " in this run)";
}

bool near(const Vec3& a, const Vec3& b) {
  const double scale = std::max({1.0, std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)});
  return std::fabs(a.x - b.x) <= 1e-9 * scale && std::fabs(a.y - b.y) <= 1e-9 * scale &&
         std::fabs(a.z - b.z) <= 1e-9 * scale;
}

}  // namespace

std::string resume_mismatch(const Manifest& old, const Manifest& now) {
  const json a = to_json(old), b = to_json(now);
  if (a["domain"] != b["domain"]) return differs("the grid (dims, origin, spacing, units)", a["domain"], b["domain"]);
  if (old.image.width != now.image.width || old.image.height != now.image.height)
    return differs("the image size ([image] width, height)", json::array({old.image.width, old.image.height}),
                   json::array({now.image.width, now.image.height}));
  if (a["video"] != b["video"]) return differs("the video settings ([video])", a["video"], b["video"]);
  if (old.movie_pattern != now.movie_pattern) return differs("the movie pattern", old.movie_pattern, now.movie_pattern);
  if (a["rig"] != b["rig"]) return differs("the rig ([rig])", a["rig"], b["rig"]);
  if (old.cameras.size() != now.cameras.size())
    return differs("the number of cameras ([rig] spec)", old.cameras.size(), now.cameras.size());
  for (std::size_t c = 0; c < old.cameras.size(); ++c) {
    const CameraEntry &p = old.cameras[c], &q = now.cameras[c];
    if (!near(p.position, q.position) || !near(p.look_at, q.look_at) || !near(p.up, q.up) ||
        std::fabs(p.fov_y_deg - q.fov_y_deg) > 1e-9 * std::max(1.0, std::fabs(p.fov_y_deg)))
      return "camera " + std::to_string(c) + " differs ([rig]: position, look-at, up or field of view)";
  }
  for (std::size_t c = 0; c < old.graph.neighbours.size() && c < now.graph.neighbours.size(); ++c) {
    const Neighbours &p = old.graph.neighbours[c], &q = now.graph.neighbours[c];
    if (p.left != q.left || p.right != q.right || p.up != q.up || p.down != q.down || p.in != q.in || p.out != q.out)
      return "the navigation graph differs at camera " + std::to_string(c) + " ([rig])";
  }
  if (old.tasks.size() != now.tasks.size())
    return differs("the number of tasks ([[task]])", old.tasks.size(), now.tasks.size());
  for (std::size_t t = 0; t < old.tasks.size(); ++t)
    if (a["tasks"][t] != b["tasks"][t])
      return differs("task " + std::to_string(t) + " (\"" + old.tasks[t].name + "\", [[task]])", a["tasks"][t], b["tasks"][t]);
  if (a["axes"] != b["axes"]) return differs("the parameter axes ([[task]] sweeps)", a["axes"], b["axes"]);
  return "";
}

}  // namespace panoptes::store
