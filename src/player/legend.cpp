#include "player/legend.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace panoptes::player {
namespace {

using nlohmann::json;

// Piecewise-linear lookup over [[x, v...], ...] control points (constant beyond the ends), as the
// renderer's TransferFunction evaluates them. Returns false when the points are malformed.
template <std::size_t N>
bool lookup(const json& points, double u, std::array<double, N>& out) {
  if (!points.is_array() || points.empty()) return false;
  auto read = [&](const json& p, double& x, std::array<double, N>& v) {
    if (!p.is_array() || p.size() != N + 1) return false;
    for (const auto& e : p)
      if (!e.is_number()) return false;
    x = p[0].get<double>();
    for (std::size_t k = 0; k < N; ++k) v[k] = p[k + 1].get<double>();
    return true;
  };
  double x0 = 0;
  std::array<double, N> v0{};
  if (!read(points[0], x0, v0)) return false;
  if (u <= x0) return out = v0, true;
  for (std::size_t i = 1; i < points.size(); ++i) {
    double x1 = 0;
    std::array<double, N> v1{};
    if (!read(points[i], x1, v1)) return false;
    if (u <= x1) {
      const double w = x1 > x0 ? (u - x0) / (x1 - x0) : 1.0;
      for (std::size_t k = 0; k < N; ++k) out[k] = v0[k] + (v1[k] - v0[k]) * w;
      return true;
    }
    x0 = x1;
    v0 = v1;
  }
  out = v0;
  return true;
}

// How opaque a slice is drawn: the renderer's slice_opacity (render/task_spec.hpp), 1 unless the task
// records another.
double slice_opacity(const json& p) {
  const auto it = p.find("slice_opacity");
  return it != p.end() && it->is_number() ? std::clamp(it->get<double>(), 0.0, 1.0) : 1.0;
}

bool number_pair(const json& p, const char* key, double& a, double& b) {
  const auto it = p.find(key);
  if (it == p.end() || !it->is_array() || it->size() != 2 || !(*it)[0].is_number() || !(*it)[1].is_number())
    return false;
  a = (*it)[0].get<double>();
  b = (*it)[1].get<double>();
  return std::isfinite(a) && std::isfinite(b);
}

bool flag(const json& p, const char* key, bool fallback) {
  const auto it = p.find(key);
  return it != p.end() && it->is_boolean() ? it->get<bool>() : fallback;
}

// The reference of `field` at `frame` (its last recorded one for later frames), or 0 if unknown.
double reference(const store::Manifest& m, const std::string& field, int frame) {
  const int f = m.find_field(field);
  if (f < 0) return 0;
  const auto& refs = m.fields[std::size_t(f)].references;
  if (refs.empty()) return 0;
  return refs[std::size_t(std::clamp(frame, 0, int(refs.size()) - 1))];
}

std::string units_of(const store::Manifest& m, const std::string& field) {
  const int f = m.find_field(field);
  return f < 0 ? std::string() : m.fields[std::size_t(f)].units;
}

// What the references of `field` follow: the manifest's word, or for older manifests "running"
// when the session kept its running maxima (it did so only in that mode), else "snapshot".
std::string reference_mode(const store::Manifest& m, const std::string& field) {
  const int f = m.find_field(field);
  if (f < 0 || m.fields[std::size_t(f)].references.empty()) return "";
  const std::string& mode = m.fields[std::size_t(f)].reference_mode;
  if (!mode.empty()) return mode;
  return m.provenance.extra.count("insitu.running_max") ? "running" : "snapshot";
}

// The reference a task's window of `field` multiplies at `frame`: the field's, or with a shared
// scale the larger of the task's fields' (as TaskPlan::resolve).
double task_reference(const store::Manifest& m, const std::vector<std::string>& fields, const std::string& field,
                      bool shared, int frame) {
  if (!shared) return reference(m, field, frame);
  double r = 0;
  for (const std::string& f : fields) {
    const double v = reference(m, f, frame);
    if (!(v > 0)) return 0;  // one unrecorded: the shared value is unknown
    r = std::max(r, v);
  }
  return r;
}

LegendBar window_bar(const store::Manifest& m, const store::TaskEntry& t, const std::string& field, const json& p,
                     const char* window_key, const char* relative_key, const char* tf_key, int frame) {
  const std::vector<std::string>& fields = t.fields;
  LegendBar bar;
  bar.field = field;
  bar.units = units_of(m, field);
  const json tf = p.contains(tf_key) ? p[tf_key] : json();
  bar.label = tf.is_object() && flag(tf, "absolute_value", false) ? "|" + field + "|" : field;
  number_pair(p, window_key, bar.lo, bar.hi);
  if (flag(p, relative_key, false)) {
    bar.shared = fields.size() > 1 && p.contains("scale") && p["scale"] == "shared";
    const double ref = task_reference(m, fields, field, bar.shared, frame);
    if (ref > 0) {
      bar.lo *= ref;
      bar.hi *= ref;
      bar.scale = reference_mode(m, field);
      if (frame > 0) {
        const double before = task_reference(m, fields, field, bar.shared, frame - 1);
        bar.change = before > 0 ? ref / before : 0;
      }
    } else {
      bar.physical = false;
    }
  }
  bar.colours = drawn_colours(t, tf_key, kLegendSamples);
  return bar;
}

}  // namespace

std::vector<std::array<float, 3>> drawn_colours(const store::TaskEntry& task, const char* tf_key, int samples) {
  std::vector<std::array<float, 3>> out;
  const json& p = task.parameters;
  if (!p.is_object() || samples < 2) return out;
  const auto it = p.find(tf_key);
  if (it == p.end() || !it->is_object() || !it->contains("colour")) return out;
  const json& tf = *it;
  // A slice is a surface: the renderer writes its colour map's colour at the slice's opacity (1, opaque,
  // unless recorded otherwise) over the black background, whatever the map's extinction says. Drawing it
  // as a volume's thin layer made the diverging map's zero (light grey on the plane) black in the legend.
  // A maximum-intensity projection (method "mip") is opaque too: the colour map at the ray's
  // maximum, alpha 1, wherever the ray crosses the domain.
  const bool slice = task.method == "slice" || task.method == "mip";
  if (!slice && !tf.contains("extinction")) return out;
  const double opacity = task.method == "slice" ? slice_opacity(p) : slice ? 1.0 : 0.0;
  for (int i = 0; i < samples; ++i) {
    const double u = double(i) / (samples - 1);
    std::array<double, 3> rgb{};
    if (!lookup(tf["colour"], u, rgb)) return {};
    double alpha = opacity;
    if (!slice) {
      // A volume: the colour with the opacity of a kLegendDepthVoxels-thick layer over black, so
      // transparent values look dark as they do in the picture.
      std::array<double, 1> sigma{};
      if (!lookup(tf["extinction"], u, sigma)) return {};
      alpha = 1 - std::exp(-std::max(0.0, sigma[0]) * kLegendDepthVoxels);
    }
    out.push_back({float(std::clamp(rgb[0], 0.0, 1.0) * alpha), float(std::clamp(rgb[1], 0.0, 1.0) * alpha),
                   float(std::clamp(rgb[2], 0.0, 1.0) * alpha)});
  }
  return out;
}

std::vector<LegendBar> task_legend(const store::Manifest& m, int task, int frame) {
  std::vector<LegendBar> bars;
  if (task < 0 || task >= m.task_count()) return bars;
  const store::TaskEntry& t = m.tasks[std::size_t(task)];
  const json& p = t.parameters;
  if (!p.is_object() || t.fields.empty()) return bars;
  double lo = 0, hi = 0;
  if (number_pair(p, "window", lo, hi)) {
    bars.push_back(window_bar(m, t, t.fields[0], p, "window", "relative", "transfer_function", frame));
    if (t.fields.size() > 1 && number_pair(p, "window2", lo, hi))
      bars.push_back(window_bar(m, t, t.fields[1], p, "window2", "relative2", "transfer_function2", frame));
  } else if (t.method == "isosurface" && p.contains("isovalue") && p["isovalue"].is_number()) {
    LegendBar bar;
    bar.field = bar.label = t.fields[0];
    bar.units = units_of(m, t.fields[0]);
    bar.isovalue = true;
    bar.lo = bar.hi = p["isovalue"].get<double>();
    if (flag(p, "relative", false)) {
      const double ref = reference(m, t.fields[0], frame);
      if (ref > 0) {
        bar.lo = bar.hi = bar.lo * ref;
        bar.scale = reference_mode(m, t.fields[0]);
        if (frame > 0) {
          const double before = reference(m, t.fields[0], frame - 1);
          bar.change = before > 0 ? ref / before : 0;
        }
      } else {
        bar.physical = false;
      }
    }
    const auto c = p.find("colour");
    if (c != p.end() && c->is_array() && c->size() == 3 && std::all_of(c->begin(), c->end(), [](const json& x) { return x.is_number(); }))
      bar.colours.push_back({std::clamp((*c)[0].get<float>(), 0.f, 1.f), std::clamp((*c)[1].get<float>(), 0.f, 1.f),
                             std::clamp((*c)[2].get<float>(), 0.f, 1.f)});
    bars.push_back(std::move(bar));
  }
  return bars;
}

std::string legend_number(double v) {
  if (v == 0 || !std::isfinite(v)) return v == 0 ? "0" : "?";
  char buf[32];
  const double a = std::abs(v);
  std::snprintf(buf, sizeof buf, a >= 1e-3 && a < 1e5 ? "%.3g" : "%.2e", v);
  return buf;
}

std::string legend_range_text(const LegendBar& bar) {
  const std::string unit = bar.physical && !bar.units.empty() ? " " + bar.units : std::string();
  const std::string rel = bar.physical ? std::string() : " x reference";
  if (bar.isovalue) return "iso " + legend_number(bar.lo) + unit + rel;
  return legend_number(bar.lo) + " .. " + legend_number(bar.hi) + unit + rel;
}

std::string legend_scale_mode_text(const LegendBar& bar, const std::string& shared_with) {
  if (bar.scale.empty()) return "";
  std::string s = bar.scale == "running" ? "running max" : bar.scale == "snapshot" ? "per snapshot" : bar.scale;
  if (bar.shared) s += shared_with.empty() ? ", shared scale" : ", shared with " + shared_with;
  return s;
}

std::string legend_change_text(const LegendBar& bar) {
  // A change smaller than the legend's 3 digits is no change to the reader.
  if (bar.scale.empty() || !(bar.change > 0) || std::abs(bar.change - 1) < 0.005) return "";
  char buf[48];
  std::snprintf(buf, sizeof buf, "x%.3g since the previous frame", bar.change);
  return buf;
}

std::string legend_scale_text(const LegendBar& bar, const std::string& shared_with) {
  const std::string mode = legend_scale_mode_text(bar, shared_with), change = legend_change_text(bar);
  return change.empty() ? mode : mode + ": " + change;
}

std::string time_text(const store::Manifest& m, double time) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "t = %.4g", time + 0.0);
  return m.time_units.empty() ? std::string(buf) : std::string(buf) + " " + m.time_units;
}

}  // namespace panoptes::player
