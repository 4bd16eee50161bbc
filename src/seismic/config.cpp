#include "seismic/config.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

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
  require(g.h > 0 && std::isfinite(g.h), "grid spacing h must be > 0, got " + std::to_string(g.h));
  require(boundary.pml_reflection > 0 && boundary.pml_reflection < 1,
          "boundary.pml_reflection must be in (0, 1), got " + std::to_string(boundary.pml_reflection));
  require(dt >= 0 && std::isfinite(dt), "dt must be >= 0 (0 = automatic), got " + std::to_string(dt));
  require(courant > 0 && courant <= 1, "courant must be in (0, 1], got " + std::to_string(courant));
  require(steps >= 0, "steps must be >= 0, got " + std::to_string(steps));
  require(record_every >= 1, "record_every must be >= 1, got " + std::to_string(record_every));
  require(attenuation.mechanisms >= 3, "attenuation.mechanisms must be >= 3, got " +
                                           std::to_string(attenuation.mechanisms));
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
  for (const auto& r : receivers) {
    require(!r.name.empty(), "a receiver has an empty name");
    require(r.name.find_first_of("/\\") == std::string::npos, "receiver name '" + r.name + "' contains a slash");
    require(inside(r.position),
            "receiver '" + r.name + "' at " + pos_str(r.position) + " is outside the non-absorbing domain " + region.str());
  }
  for (std::size_t i = 0; i < receivers.size(); ++i)
    for (std::size_t j = i + 1; j < receivers.size(); ++j)
      require(receivers[i].name != receivers[j].name, "two receivers are named '" + receivers[i].name + "'");
}

}  // namespace panoptes::seismic
