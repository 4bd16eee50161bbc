#include "seismic/config.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <string_view>
#include <unordered_set>

#include "core/error.hpp"

namespace panoptes::seismic {

SourceSpec SourceSpec::explosion(std::array<double, 3> pos, double m0, SourceTimeFunction stf) {
  SourceSpec s;
  s.kind = Kind::moment;
  s.position = pos;
  s.moment = {m0, m0, m0, 0, 0, 0};
  s.stf = stf;
  return s;
}

SourceSpec SourceSpec::double_couple(std::array<double, 3> pos, double strike, double dip, double rake, double m0,
                                     SourceTimeFunction stf) {
  const double d2r = std::numbers::pi / 180.0;
  const double f = strike * d2r, d = dip * d2r, l = rake * d2r;
  using std::cos;
  using std::sin;
  SourceSpec s;
  s.kind = Kind::moment;
  s.position = pos;
  s.stf = stf;
  // Aki & Richards (2002) box 4.4, x = north, y = east, z = down.
  const double mxx = -m0 * (sin(d) * cos(l) * sin(2 * f) + sin(2 * d) * sin(l) * sin(f) * sin(f));
  const double mxy = m0 * (sin(d) * cos(l) * cos(2 * f) + 0.5 * sin(2 * d) * sin(l) * sin(2 * f));
  const double mxz = -m0 * (cos(d) * cos(l) * cos(f) + cos(2 * d) * sin(l) * sin(f));
  const double myy = m0 * (sin(d) * cos(l) * sin(2 * f) - sin(2 * d) * sin(l) * cos(f) * cos(f));
  const double myz = -m0 * (cos(d) * cos(l) * sin(f) - cos(2 * d) * sin(l) * cos(f));
  const double mzz = m0 * sin(2 * d) * sin(l);
  s.moment = {mxx, myy, mzz, mxy, mxz, myz};
  return s;
}

SourceSpec SourceSpec::point_force(std::array<double, 3> pos, std::array<double, 3> f, SourceTimeFunction stf) {
  SourceSpec s;
  s.kind = Kind::force;
  s.position = pos;
  s.force = f;
  s.stf = stf;
  return s;
}

double SolverConfig::dominant_frequency() const {
  double f = 0;
  for (const auto& s : sources)
    f = std::max(f, s.stf.kind == SourceTimeFunction::Kind::ricker ? s.stf.frequency : 1.0 / s.stf.duration);
  return f > 0 ? f : 1.0;
}

namespace {
std::string pos_str(const std::array<double, 3>& p) {
  std::ostringstream s;
  s << "(" << p[0] << ", " << p[1] << ", " << p[2] << ") m";
  return s.str();
}
}  // namespace

void SolverConfig::validate() const {
  const auto& g = grid;
  const int n = boundary.pml_cells;
  require(n >= 0, "boundary.pml_cells must be >= 0, got " + std::to_string(n));
  require(g.nx >= 2 * n + 5 && g.ny >= 2 * n + 5 && g.nz >= 2 * n + 5,
          "grid " + std::to_string(g.nx) + "x" + std::to_string(g.ny) + "x" + std::to_string(g.nz) +
              " is too small: every axis needs at least 2*pml_cells + 5 = " + std::to_string(2 * n + 5) + " nodes");
  // The solver indexes a plane of the ghosted grid with int: keep nx·ny (and each axis) well inside it.
  require(g.nx <= kMaxAxisNodes && g.ny <= kMaxAxisNodes && g.nz <= kMaxAxisNodes &&
              (long long)(g.nx + 4) * (g.ny + 4) <= kMaxPlaneNodes,
          "grid " + std::to_string(g.nx) + "x" + std::to_string(g.ny) + "x" + std::to_string(g.nz) +
              " is too large: expected at most " + std::to_string(kMaxAxisNodes) + " nodes per axis and " +
              std::to_string(kMaxPlaneNodes) + " nodes per x-y plane");
  require(g.h > 0 && std::isfinite(g.h), "grid spacing h must be > 0, got " + std::to_string(g.h));
  require(boundary.pml_reflection > 0 && boundary.pml_reflection < 1,
          "boundary.pml_reflection must be in (0, 1), got " + std::to_string(boundary.pml_reflection));
  require(dt >= 0 && std::isfinite(dt), "dt must be >= 0 (0 = automatic), got " + std::to_string(dt));
  require(courant > 0 && courant <= 1, "courant must be in (0, 1], got " + std::to_string(courant));
  require(steps >= 0, "steps must be >= 0, got " + std::to_string(steps));
  require(record_every >= 1, "record_every must be >= 1, got " + std::to_string(record_every));
  require(attenuation.mechanisms >= 3, "attenuation.mechanisms must be >= 3, got " +
                                           std::to_string(attenuation.mechanisms));
  if (medium.kind == MediumSpec::Kind::layered) {
    // Depth is positive down from the surface z = 0; a layer cannot start above it, and each layer
    // starts below the previous one (otherwise the earlier one has no thickness and is silently lost).
    require(!medium.layers.empty(), "medium: no layers given");
    for (std::size_t l = 0; l < medium.layers.size(); ++l) {
      const Layer& L = medium.layers[l];
      require(std::isfinite(L.top), "medium.layer[" + std::to_string(l) + "].top is not a finite depth");
      require(l > 0 || L.top == 0, "medium.layer[0].top = " + std::to_string(L.top) +
                                       " m; the first layer must start at the surface, depth 0 (z is positive down)");
      require(L.top >= 0, "medium.layer[" + std::to_string(l) + "].top = " + std::to_string(L.top) +
                              " m lies above the surface (depth 0; z is positive down)");
      // The message names layer l − 1: build it only when there is one (found by fuzz_toml_config:
      // an eager message read layers[-1] for a homogeneous medium).
      if (l > 0 && !(L.top > medium.layers[l - 1].top))
        throw Error("medium.layer[" + std::to_string(l) + "].top = " + std::to_string(L.top) + " m is not below layer " +
                    std::to_string(l - 1) + "'s top " + std::to_string(medium.layers[l - 1].top) +
                    " m; list the layers from the surface down");
    }
  }
  // The non-absorbing region every source and receiver must lie in.
  const double lo[3] = {n * g.h, n * g.h, boundary.free_surface ? 0.0 : n * g.h};
  const double hi[3] = {(g.nx - 1 - n) * g.h, (g.ny - 1 - n) * g.h, (g.nz - 1 - n) * g.h};
  auto inside = [&](const std::array<double, 3>& p) {
    for (int a = 0; a < 3; ++a)
      if (!(p[a] >= lo[a] - 1e-9 * g.h && p[a] <= hi[a] + 1e-9 * g.h)) return false;
    return true;
  };
  std::ostringstream region;
  region << "[" << lo[0] << ", " << hi[0] << "] x [" << lo[1] << ", " << hi[1] << "] x [" << lo[2] << ", " << hi[2]
         << "] m";
  for (std::size_t i = 0; i < sources.size(); ++i) {
    require(inside(sources[i].position), "source " + std::to_string(i) + " at " + pos_str(sources[i].position) +
                                             " is outside the non-absorbing domain " + region.str());
    for (double m : sources[i].moment) require(std::isfinite(m), "source " + std::to_string(i) + ": non-finite moment");
    for (double f : sources[i].force) require(std::isfinite(f), "source " + std::to_string(i) + ": non-finite force");
  }
  // Messages are built only on failure, and names go into a set (not compared pairwise): receiver
  // lines give up to 10^5 receivers each.
  std::unordered_set<std::string_view> names;
  names.reserve(receivers.size());
  for (const auto& r : receivers) {
    if (r.name.empty()) throw Error("a receiver has an empty name");
    if (r.name.find_first_of("/\\") != std::string::npos)
      throw Error("receiver name '" + r.name + "' contains a slash");
    if (!inside(r.position))
      throw Error("receiver '" + r.name + "' at " + pos_str(r.position) + " is outside the non-absorbing domain " +
                  region.str());
    if (!names.insert(r.name).second) throw Error("two receivers are named '" + r.name + "'");
  }
}

}  // namespace panoptes::seismic
