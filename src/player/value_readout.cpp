#include "player/value_readout.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "camera/camera.hpp"
#include "core/error.hpp"
#include "player/legend.hpp"
#include "player/look.hpp"

namespace panoptes::player {
namespace {

using nlohmann::json;

// As the renderer turns a colour in [0, 1] into a byte (render/partial_image.cpp, to_byte).
std::uint8_t readout_byte(float c) {
  const float v = (c > 0.0f ? std::min(c, 1.0f) : 0.0f) * 255.0f;
  return std::uint8_t(int(double(v) + 0.5));
}

double rgb_distance(const std::array<std::uint8_t, 3>& a, const std::array<int, 3>& b) {
  const double dr = double(a[0]) - b[0], dg = double(a[1]) - b[1], db = double(a[2]) - b[2];
  return std::sqrt(dr * dr + dg * dg + db * db);
}

}  // namespace

double SliceReadout::resolution() const {
  return table.colours.empty() ? 0 : std::abs(hi - lo) / double(table.colours.size());
}

SliceReadout slice_readout(const store::Manifest& m, int task, int frame) {
  SliceReadout r;
  if (task < 0 || task >= m.task_count()) return r;
  const store::TaskEntry& t = m.tasks[std::size_t(task)];
  if (t.method != "slice" || !t.parameters.is_object()) return r;
  // The window as the legend shows it at this frame: one rule for the bar and the readout.
  const auto bars = task_legend(m, task, frame);
  if (bars.empty() || bars[0].isovalue) return r;
  const LegendBar& bar = bars[0];
  r.field = bar.field, r.label = bar.label, r.units = bar.units;
  r.lo = bar.lo, r.hi = bar.hi, r.physical = bar.physical;
  // The renderer's bins sample the map at their centres (i + 0.5) / kReadoutBins: the odd samples of
  // 2·kReadoutBins + 1 evenly spaced ones.
  const auto fine = drawn_colours(t, "transfer_function", 2 * kReadoutBins + 1);
  if (fine.size() != std::size_t(2 * kReadoutBins + 1)) return r;
  double u_sum = 0;
  int run = 0;
  for (int i = 0; i < kReadoutBins; ++i) {
    const auto& c = fine[std::size_t(2 * i + 1)];
    const std::array<std::uint8_t, 3> q{readout_byte(c[0]), readout_byte(c[1]), readout_byte(c[2])};
    const double u = (i + 0.5) / kReadoutBins;
    if (!r.table.colours.empty() && r.table.colours.back() == q) {
      u_sum += u, ++run;
      r.table.u.back() = u_sum / run;
      continue;
    }
    r.table.colours.push_back(q);
    r.table.u.push_back(u);
    u_sum = u, run = 1;
  }
  r.usable = std::isfinite(r.lo) && std::isfinite(r.hi) && r.hi != r.lo && !r.table.colours.empty();
  // The plane, for telling pixels off the slice by geometry; without it (a task that does not record
  // it, a manifest without the domain) the colour alone decides.
  const json& p = t.parameters;
  const auto axis = p.find("axis");
  const auto position = p.find("position");
  if (axis == p.end() || !axis->is_string() || position == p.end() || !position->is_number()) return r;
  const std::string a = axis->get<std::string>();
  if (a != "x" && a != "y" && a != "z") return r;
  r.axis = a[0] - 'x';
  r.position = position->get<double>();
  const auto& d = m.domain;
  if (std::isfinite(r.position) && d.dims[0] >= 2 && d.dims[1] >= 2 && d.dims[2] >= 2) {
    r.have_box = true;
    r.box_lo = d.origin;
    r.box_hi = {d.origin.x + double(d.dims[0] - 1) * d.spacing.x, d.origin.y + double(d.dims[1] - 1) * d.spacing.y,
                d.origin.z + double(d.dims[2] - 1) * d.spacing.z};
  }
  return r;
}

ValueReading read_colour(const SliceReadout& r, std::array<int, 3> rgb) {
  ValueReading out;
  out.resolution = r.resolution();
  if (!r.usable) {
    out.reason = "not a slice";
    return out;
  }
  const auto& cs = r.table.colours;
  std::size_t best = 0;
  double dbest = rgb_distance(cs[0], rgb);
  for (std::size_t i = 1; i < cs.size(); ++i) {
    const double d = rgb_distance(cs[i], rgb);
    if (d < dbest) dbest = d, best = i;
  }
  out.colour_distance = dbest;
  if (dbest > kReadoutMaxDistance) {
    out.reason = "not a colour of the map";
    return out;
  }
  // Every colour about as close as the best one: if they lie far apart along the map, the colour
  // does not name one value.
  double umin = r.table.u[best], umax = umin;
  for (std::size_t i = 0; i < cs.size(); ++i)
    if (rgb_distance(cs[i], rgb) <= dbest + kReadoutMargin) {
      umin = std::min(umin, r.table.u[i]);
      umax = std::max(umax, r.table.u[i]);
    }
  if (umax - umin > kReadoutMaxSpread) {
    out.reason = "ambiguous colour";
    return out;
  }
  // The map is constant beyond its ends: its first and last colours stand for every value past them.
  if (best == 0 || best + 1 == cs.size()) {
    out.kind = best == 0 ? ValueReading::Kind::below : ValueReading::Kind::above;
    out.value = best == 0 ? r.lo : r.hi;
    return out;
  }
  out.kind = ValueReading::Kind::value;
  // The mean position of the colours within kReadoutCentroidBand of the best: H.264's noise moves a
  // colour off the map's curve, and several neighbours along it then match about equally.
  double su = 0, n = 0;
  for (std::size_t i = 0; i < cs.size(); ++i)
    if (rgb_distance(cs[i], rgb) <= dbest + kReadoutCentroidBand) su += r.table.u[i], n += 1;
  out.value = r.lo + su / n * (r.hi - r.lo);
  out.uncertainty = kReadoutUncertaintySteps * out.resolution;
  return out;
}

bool pixel_on_slice(const store::Manifest& m, const SliceReadout& r, int camera, int x, int y) {
  if (!r.have_box) return true;
  if (camera < 0 || camera >= m.camera_count() || m.image.width <= 0 || m.image.height <= 0) return true;
  const store::CameraEntry& c = m.cameras[std::size_t(camera)];
  camera::Ray ray;
  try {
    const camera::Camera cam(c.position, c.look_at, c.up, c.fov_y_deg, m.image.width, m.image.height,
                             is_equirectangular(m) ? camera::Projection::equirectangular : camera::Projection::perspective);
    ray = cam.ray(x + 0.5, y + 0.5);
  } catch (const Error&) {
    return true;  // a camera the renderer would refuse: no geometry to go by
  }
  const int a = r.axis;
  if (ray.direction[a] == 0) return false;
  const double t = (r.position - ray.origin[a]) / ray.direction[a];
  if (!(t > 0)) return false;
  const Vec3 p = ray.origin + ray.direction * t;
  for (int b = 0; b < 3; ++b) {
    if (b == a) continue;
    const double slack = 1e-9 * (r.box_hi[b] - r.box_lo[b]);
    if (p[b] < r.box_lo[b] - slack || p[b] > r.box_hi[b] + slack) return false;
  }
  return true;
}

ValueReading read_pixel(const store::Manifest& m, const SliceReadout& r, int camera, int x, int y,
                        std::array<int, 3> rgb) {
  if (r.usable && !pixel_on_slice(m, r, camera, x, y)) {
    ValueReading out;
    out.resolution = r.resolution();
    out.reason = "off the slice";
    return out;
  }
  return read_colour(r, rgb);
}

std::string reading_text(const SliceReadout& r, const ValueReading& v) {
  if (v.kind == ValueReading::Kind::none) return "no reading: " + v.reason;
  const std::string unit = r.physical && !r.units.empty() ? " " + r.units : "";
  const std::string rel = r.physical ? "" : " x reference";
  switch (v.kind) {
    case ValueReading::Kind::below:
      return r.label + " <= " + legend_number(v.value) + unit + rel;
    case ValueReading::Kind::above:
      return r.label + " >= " + legend_number(v.value) + unit + rel;
    default:
      return r.label + " = " + legend_number(v.value) + unit + rel + "  (+-" + legend_number(v.uncertainty) + ")";
  }
}

std::array<int, 3> rgb_at(const video::YuvFrame& f, int x, int y) {
  if (x < 0 || y < 0 || x >= f.width || y >= f.height)
    throw Error("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                std::to_string(f.width) + "x" + std::to_string(f.height) + " frame");
  const int cw = (f.width + 1) / 2;
  const double Y = f.y[std::size_t(y) * std::size_t(f.width) + std::size_t(x)];
  const std::size_t ci = std::size_t(y / 2) * std::size_t(cw) + std::size_t(x / 2);
  const double U = double(f.u[ci]) - 128, V = double(f.v[ci]) - 128;
  // BT.601, limited range (what the movies' colour tags say and the players' converters use).
  const double L = 1.164383562 * (Y - 16);
  auto clamp8 = [](double v) { return int(std::clamp(std::lround(v), 0L, 255L)); };
  return {clamp8(L + 1.596026786 * V), clamp8(L - 0.391762290 * U - 0.812967647 * V), clamp8(L + 2.017232143 * U)};
}

json slice_readout_json(const store::Manifest& m, int task) {
  const SliceReadout r = slice_readout(m, task, 0);
  if (!r.usable) return nullptr;
  json colours = json::array(), u = json::array();
  for (const auto& c : r.table.colours) colours.push_back({c[0], c[1], c[2]});
  for (const double x : r.table.u) u.push_back(std::round(x * 1e6) / 1e6);  // 1/1000 of a bin
  json j = {{"colours", std::move(colours)}, {"u", std::move(u)},  {"axis", r.axis},
            {"position", r.position},        {"max_distance", kReadoutMaxDistance},
            {"margin", kReadoutMargin},      {"max_spread", kReadoutMaxSpread},
            {"centroid_band", kReadoutCentroidBand}, {"uncertainty_steps", kReadoutUncertaintySteps}};
  if (r.have_box) {
    j["box_lo"] = {r.box_lo.x, r.box_lo.y, r.box_lo.z};
    j["box_hi"] = {r.box_hi.x, r.box_hi.y, r.box_hi.z};
  }
  return j;
}

}  // namespace panoptes::player
