#include "insitu/task_plan.hpp"

// Sections, in order: the [[task]] table (parse_task_table), sweeps (planned_task_count), the plan
// (TaskPlan: specs, axes, manifest entries; share_scales; resolve), the --task shorthand
// (parse_task_shorthand, tasks_from_shorthand), the table printed back (task_table_toml), and each
// kind's words for help and errors (kind_help, task_shorthand_syntax, task_tables_help).
#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "core/number_text.hpp"
#include "core/toml_keys.hpp"

namespace panoptes::insitu {

namespace {

// The transfer function as data (control points), so players draw its colour legend without knowing
// the renderer's presets (issue 34).
nlohmann::json transfer_json(const render::TransferFunction& tf) {
  // The presets are floats: 0.9f would read 0.8999999761581421 in the manifest.
  const auto v = [](float x) { return std::round(double(x) * 1e6) / 1e6; };
  nlohmann::json colour = nlohmann::json::array(), extinction = nlohmann::json::array();
  for (const auto& p : tf.colour) colour.push_back({v(p.x), v(p.colour.r), v(p.colour.g), v(p.colour.b)});
  for (const auto& p : tf.opacity) extinction.push_back({v(p.x), v(p.extinction)});
  return {{"colour", std::move(colour)}, {"extinction", std::move(extinction)}, {"absolute_value", tf.absolute_value}};
}

render::ValueWindow window_of(const WindowConfig& w) {
  return w.relative ? render::ValueWindow::relative_to(w.lo, w.hi) : render::ValueWindow::absolute(w.lo, w.hi);
}

// A volume of two fields (the paper's p- and s-waves in one image) is a render volume; TOML spells it
// "volume2" so that a one-field volume's window sweeps and a two-field volume's keys stay apart.
constexpr const char* kVolume2 = "volume2";

bool two_fields(const TaskConfig& t) { return t.kind == render::TaskKind::volume && t.fields.size() == 2; }

WindowConfig window_at(const toml_keys::Source& c, const toml::node& n, const std::string& key, bool relative) {
  const auto v = toml_keys::numbers(c, n, key);
  if (v.size() != 2 || !(v[0] < v[1])) c.fail(key, "expected [lo, hi] with lo < hi");
  return {v[0], v[1], relative};
}

}  // namespace

TaskConfig parse_task_table(const toml_keys::Source& c, const toml::table& t, std::size_t index) {
  using toml_keys::boolean;
  using toml_keys::num;
  using toml_keys::number_of;
  using toml_keys::numbers;
  using toml_keys::str;
  const std::string where = "task[" + std::to_string(index) + "].";
  TaskConfig tc;
  const std::string type = str(c, t, "type", where, "volume");
  const bool volume2 = type == kVolume2;
  try {
    tc.kind = volume2 ? render::TaskKind::volume : render::parse_task_kind(type);
  } catch (const Error&) {
    c.fail(where + "type", "\"" + type + "\"; expected " + render::task_kind_words(kVolume2));
  }
  std::set<std::string> allowed{"type", "name", "field", "fields"};
  switch (tc.kind) {
    case render::TaskKind::volume:
      if (volume2) allowed.insert({"preset", "preset2", "extinction_scale", "window", "window2", "relative"});
      else allowed.insert({"preset", "extinction_scale", "window", "windows", "relative", "axis_name"});
      break;
    case render::TaskKind::isosurface: allowed.insert({"isovalues", "isovalue", "relative", "colour", "axis_name"}); break;
    case render::TaskKind::slice:
      allowed.insert({"preset", "window", "relative", "axis", "position", "positions", "axis_name"});
      break;
    case render::TaskKind::mip: allowed.insert({"preset", "window", "relative"}); break;
  }
  toml_keys::only_keys(c, t, where.substr(0, where.size() - 1), allowed);
  tc.name = str(c, t, "name", where, "");
  if (tc.name.empty()) c.fail(where + "name", "missing (every task needs a unique name)");
  if (const auto* f = t.get("field")) {
    if (t.get("fields")) c.fail(where + "field", "give either field or fields, not both");
    auto s = f->value_exact<std::string>();
    if (!s || s->empty()) c.fail(where + "field", "expected a field name");
    tc.fields = {*s};
  } else if (const auto* fs = t.get("fields")) {
    const auto* a = fs->as_array();
    if (!a) c.fail(where + "fields", "expected an array of field names");
    for (std::size_t i = 0; i < a->size(); ++i) {
      auto s = a->get(i)->value_exact<std::string>();
      if (!s || s->empty()) c.fail(where + "fields", "expected an array of field names");
      tc.fields.push_back(*s);
    }
  }
  const std::size_t want = volume2 ? 2 : 1;
  if (tc.fields.size() != want)
    c.fail(where + (want == 2 ? "fields" : "field"),
           want == 2 ? "a volume2 task reads exactly two fields: fields = [\"a\", \"b\"]"
                     : "this task reads exactly one field: field = \"name\"");
  const bool relative = boolean(c, t, "relative", where, true);
  tc.axis = str(c, t, "axis_name", where, "");
  auto check_preset = [&](const std::string& key, const std::string& p) {
    const auto names = render::TransferFunction::preset_names();
    if (std::find(names.begin(), names.end(), p) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      c.fail(where + key, "unknown preset \"" + p + "\" (expected one of: " + list + ")");
    }
  };
  switch (tc.kind) {
    case render::TaskKind::volume:
      tc.preset = str(c, t, "preset", where, volume2 ? "p-wave" : "hot");
      check_preset("preset", tc.preset);
      tc.extinction_scale = float(num(c, t, "extinction_scale", where, 1));
      if (!(tc.extinction_scale > 0)) c.fail(where + "extinction_scale", "expected a number > 0");
      if (const auto* ws = t.get("windows")) {
        if (t.get("window")) c.fail(where + "windows", "give either window or windows, not both");
        const auto* a = ws->as_array();
        if (!a || a->empty()) c.fail(where + "windows", "expected an array of [lo, hi] pairs");
        tc.windows.clear();
        for (std::size_t i = 0; i < a->size(); ++i)
          tc.windows.push_back(window_at(c, *a->get(i), where + "windows[" + std::to_string(i) + "]", relative));
      } else {
        tc.windows = {t.get("window") ? window_at(c, *t.get("window"), where + "window", relative)
                                      : WindowConfig{0, 1, relative}};
      }
      if (volume2) {
        tc.preset2 = str(c, t, "preset2", where, "s-wave");
        check_preset("preset2", tc.preset2);
        tc.window2 = t.get("window2") ? window_at(c, *t.get("window2"), where + "window2", relative)
                                      : WindowConfig{0, 1, relative};
      }
      break;
    case render::TaskKind::isosurface:
      tc.iso_relative = boolean(c, t, "relative", where, false);
      if (const auto* v = t.get("isovalues")) {
        if (t.get("isovalue")) c.fail(where + "isovalues", "give either isovalue or isovalues, not both");
        tc.isovalues = numbers(c, *v, where + "isovalues");
      } else if (const auto* v1 = t.get("isovalue")) {
        tc.isovalues = {number_of(c, *v1, where + "isovalue")};
      }
      if (tc.isovalues.empty()) c.fail(where + "isovalues", "missing (at least one isovalue is required)");
      if (const auto* col = t.get("colour")) tc.colour = toml_keys::colour(c, *col, where + "colour");
      break;
    case render::TaskKind::slice: {
      tc.preset = str(c, t, "preset", where, "diverging");
      check_preset("preset", tc.preset);
      tc.windows = {t.get("window") ? window_at(c, *t.get("window"), where + "window", relative)
                                    : WindowConfig{-1, 1, relative}};
      const std::string axis = str(c, t, "axis", where, "z");
      if (axis != "x" && axis != "y" && axis != "z") c.fail(where + "axis", "\"" + axis + "\"; expected x, y or z");
      tc.slice_axis = axis[0] - 'x';
      if (const auto* p = t.get("positions")) {
        if (t.get("position")) c.fail(where + "positions", "give either position or positions, not both");
        tc.slice_positions = numbers(c, *p, where + "positions");
      } else if (const auto* p1 = t.get("position")) {
        tc.slice_positions = {number_of(c, *p1, where + "position")};
      }
      if (tc.slice_positions.empty()) c.fail(where + "positions", "expected at least one position");
      for (double f : tc.slice_positions)
        if (!(f >= 0 && f <= 1)) c.fail(where + "positions", "expected fractions of the domain in [0, 1]");
      break;
    }
    case render::TaskKind::mip:
      tc.preset = str(c, t, "preset", where, "hot");
      check_preset("preset", tc.preset);
      tc.windows = {t.get("window") ? window_at(c, *t.get("window"), where + "window", relative)
                                    : WindowConfig{tc.preset == "diverging" ? -1.0 : 0.0, 1, relative}};
      break;
  }
  return tc;
}

std::size_t planned_task_count(const TaskConfig& t) {
  switch (t.kind) {
    case render::TaskKind::volume: return two_fields(t) ? 1 : t.windows.size();
    case render::TaskKind::isosurface: return t.isovalues.size();
    case render::TaskKind::slice: return t.slice_positions.size();
    case render::TaskKind::mip: return 1;
  }
  return 1;
}

TaskPlan::TaskPlan(const std::vector<TaskConfig>& configs, const render::GridGeometry& grid) {
  auto field_index = [&](const std::string& name) {
    auto it = std::find(field_names_.begin(), field_names_.end(), name);
    if (it != field_names_.end()) return int(it - field_names_.begin());
    field_names_.push_back(name);
    return int(field_names_.size()) - 1;
  };
  for (const TaskConfig& tc : configs) {
    const int f = field_index(tc.fields.at(0));
    const int f2 = tc.fields.size() > 1 ? field_index(tc.fields[1]) : -1;
    std::size_t n = 1;
    std::string axis_suffix;
    std::vector<double> axis_values;
    switch (tc.kind) {
      case render::TaskKind::volume:
        if (two_fields(tc)) break;
        n = tc.windows.size();
        axis_suffix = "window";
        for (const auto& w : tc.windows) axis_values.push_back(w.hi);
        break;
      case render::TaskKind::isosurface:
        n = tc.isovalues.size();
        axis_suffix = "isovalue";
        axis_values = tc.isovalues;
        break;
      case render::TaskKind::slice:
        n = tc.slice_positions.size();
        axis_suffix = "position";
        axis_values = tc.slice_positions;
        break;
      case render::TaskKind::mip: break;
    }
    const std::string axis_name = tc.axis.empty() ? tc.name + " " + axis_suffix : tc.axis;
    if (n > 1) axes_.push_back({axis_name, axis_values, ""});
    for (std::size_t i = 0; i < n; ++i) {
      PlannedTask t;
      t.entry.name = n > 1 ? tc.name + " " + number_text(axis_values[i]) : tc.name;
      t.entry.fields = tc.fields;
      if (n > 1) t.entry.axes = {{axis_name, int(i)}};
      switch (tc.kind) {
        case render::TaskKind::volume: {
          if (two_fields(tc)) {
            const WindowConfig& w = tc.windows[0];
            t.spec = render::TaskSpec::volume2(f, render::TransferFunction::preset(tc.preset, tc.extinction_scale),
                                               window_of(w), f2,
                                               render::TransferFunction::preset(tc.preset2, tc.extinction_scale),
                                               window_of(tc.window2));
            t.relative = w.relative;
            t.relative2 = tc.window2.relative;
            t.entry.method = "volume";
            t.entry.parameters = {{"preset", tc.preset},         {"window", {w.lo, w.hi}},
                                  {"preset2", tc.preset2},       {"window2", {tc.window2.lo, tc.window2.hi}},
                                  {"relative", w.relative},      {"extinction_scale", tc.extinction_scale},
                                  {"relative2", tc.window2.relative},
                                  {"transfer_function", transfer_json(t.spec.tf)},
                                  {"transfer_function2", transfer_json(t.spec.tf2)}};
            break;
          }
          const WindowConfig& w = tc.windows[i];
          t.spec = render::TaskSpec::volume(f, render::TransferFunction::preset(tc.preset, tc.extinction_scale), window_of(w));
          t.relative = w.relative;
          t.entry.method = "volume";
          t.entry.parameters = {{"preset", tc.preset}, {"window", {w.lo, w.hi}}, {"relative", w.relative},
                                {"extinction_scale", tc.extinction_scale},
                                {"transfer_function", transfer_json(t.spec.tf)}};
          break;
        }
        case render::TaskKind::isosurface:
          t.spec = render::TaskSpec::isosurface(f, float(tc.isovalues[i]), {tc.colour[0], tc.colour[1], tc.colour[2]});
          t.iso_relative = tc.iso_relative;
          t.iso_fraction = tc.isovalues[i];
          t.entry.method = "isosurface";
          t.entry.parameters = {{"isovalue", tc.isovalues[i]}, {"relative", tc.iso_relative},
                                {"colour", {tc.colour[0], tc.colour[1], tc.colour[2]}}};
          break;
        case render::TaskKind::slice: {
          const WindowConfig& w = tc.windows[0];
          const int a = tc.slice_axis;
          const double pos = grid.origin[a] + tc.slice_positions[i] * (grid.dims[a] - 1) * grid.spacing[a];
          t.spec = render::TaskSpec::slice(f, a, pos, render::TransferFunction::preset(tc.preset), window_of(w));
          t.relative = w.relative;
          t.entry.method = "slice";
          t.entry.parameters = {{"axis", std::string(1, char('x' + a))}, {"fraction", tc.slice_positions[i]},
                                {"position", pos}, {"preset", tc.preset}, {"window", {w.lo, w.hi}},
                                {"relative", w.relative}, {"transfer_function", transfer_json(t.spec.tf)}};
          break;
        }
        case render::TaskKind::mip: {
          const WindowConfig& w = tc.windows[0];
          t.spec = render::TaskSpec::mip(f, render::TransferFunction::preset(tc.preset), window_of(w));
          t.relative = w.relative;
          t.entry.method = "mip";
          t.entry.parameters = {{"preset", tc.preset}, {"window", {w.lo, w.hi}}, {"relative", w.relative},
                                {"transfer_function", transfer_json(t.spec.tf)}};
          break;
        }
      }
      t.entry.id = int(tasks_.size());
      for (const PlannedTask& o : tasks_)
        if (o.entry.name == t.entry.name) throw Error("task \"" + t.entry.name + "\": the name is used twice");
      tasks_.push_back(std::move(t));
    }
  }
}

void TaskPlan::share_scales(const std::map<std::string, std::string>& field_units, ScaleSharing sharing) {
  auto unit = [&](const std::string& f) {
    const auto it = field_units.find(f);
    return it == field_units.end() ? std::string() : it->second;
  };
  for (PlannedTask& t : tasks_) {
    if (t.spec.field2 < 0 || t.entry.fields.size() < 2) continue;
    const std::string a = unit(t.entry.fields[0]), b = unit(t.entry.fields[1]);
    // Fields of different units cannot be compared, so each keeps its own; unknown units are taken
    // as comparable: a shared scale can hide a weak field, an own scale invents strength it lacks.
    t.shared = sharing == ScaleSharing::units && (a == b || a.empty() || b.empty());
    t.entry.parameters["scale"] = t.shared ? "shared" : "own";
  }
}

void TaskPlan::resolve(const std::vector<double>& ref, std::vector<render::TaskSpec>& specs) const {
  specs.resize(tasks_.size());
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    const PlannedTask& t = tasks_[i];
    render::TaskSpec& s = specs[i];
    s = t.spec;
    const double r1 = ref[std::size_t(t.spec.field)];
    const double r2 = t.spec.field2 >= 0 ? ref[std::size_t(t.spec.field2)] : 0;
    const double shared = std::max(r1, r2);
    if (t.relative) s.reference = t.shared ? shared : r1;
    if (t.relative2 && t.spec.field2 >= 0) s.reference2 = t.shared ? shared : r2;
    if (t.iso_relative) s.isovalue = float(t.iso_fraction * ref[std::size_t(t.spec.field)]);
  }
}

TaskConfig parse_task_shorthand(const std::string& text, const std::string& field) {
  std::vector<std::string> parts;
  std::size_t b = 0;
  while (true) {
    const auto e = text.find(':', b);
    parts.push_back(text.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  const std::string usage = "; expected " + task_shorthand_syntax();
  auto number = [&](const std::string& s) {
    try {
      std::size_t used = 0;
      const double v = std::stod(s, &used);
      if (used != s.size() || !std::isfinite(v)) throw std::invalid_argument("");
      return v;
    } catch (const std::exception&) {
      throw Error("--task \"" + text + "\": \"" + s + "\" is not a number");
    }
  };
  auto preset = [&](const std::string& p) {
    const auto names = render::TransferFunction::preset_names();
    if (std::find(names.begin(), names.end(), p) != names.end()) return p;
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw Error("--task \"" + text + "\": unknown preset \"" + p + "\" (expected one of: " + list + ")");
  };
  auto absolute = [&](const std::string& lo, const std::string& hi) {
    const WindowConfig w{number(lo), number(hi), false};
    if (!(w.lo < w.hi)) throw Error("--task \"" + text + "\": window " + lo + ":" + hi + "; expected LO < HI");
    return w;
  };
  TaskConfig t;
  t.name = text;
  t.fields = {field};
  // The first word is a render::TaskKind word; "iso" abbreviates "isosurface".
  try {
    t.kind = render::parse_task_kind(parts[0] == "iso" ? "isosurface" : parts[0]);
  } catch (const Error&) {
    throw Error("--task \"" + text + "\"" + usage);
  }
  switch (t.kind) {
    case render::TaskKind::volume:
      if (parts.size() != 2 && parts.size() != 4) throw Error("--task \"" + text + "\"" + usage);
      t.preset = preset(parts[1]);
      // Relative default: [0, ref] (|v| for the wave presets), [-ref, ref] for the diverging map.
      t.windows = {parts.size() == 4 ? absolute(parts[2], parts[3])
                                     : WindowConfig{t.preset == "diverging" ? -1.0 : 0.0, 1.0, true}};
      break;
    case render::TaskKind::isosurface:
      if (parts.size() != 2) throw Error("--task \"" + text + "\"" + usage);
      t.isovalues = {number(parts[1])};
      break;
    case render::TaskKind::slice: {
      if (parts.size() != 3 && parts.size() != 4 && parts.size() != 6) throw Error("--task \"" + text + "\"" + usage);
      const std::string axes = "xyz";
      if (parts[1].size() != 1 || axes.find(parts[1][0]) == std::string::npos)
        throw Error("--task \"" + text + "\": slice axis \"" + parts[1] + "\"; expected x, y or z");
      t.slice_axis = int(axes.find(parts[1][0]));
      const double f = number(parts[2]);
      if (!(f >= 0 && f <= 1)) throw Error("--task \"" + text + "\": slice position " + parts[2] + "; expected a fraction in [0, 1]");
      t.slice_positions = {f};
      t.preset = parts.size() >= 4 ? preset(parts[3]) : "diverging";
      t.windows = {parts.size() == 6 ? absolute(parts[4], parts[5]) : WindowConfig{-1, 1, true}};
      break;
    }
    case render::TaskKind::mip:  // the window as a volume's
      if (parts.size() != 2 && parts.size() != 4) throw Error("--task \"" + text + "\"" + usage);
      t.preset = preset(parts[1]);
      t.windows = {parts.size() == 4 ? absolute(parts[2], parts[3])
                                     : WindowConfig{t.preset == "diverging" ? -1.0 : 0.0, 1.0, true}};
      break;
  }
  return t;
}

std::vector<TaskConfig> tasks_from_shorthand(const std::vector<std::string>& texts, const std::string& field) {
  std::vector<TaskConfig> tasks;
  int isos = 0;
  for (const std::string& text : texts) {
    for (const TaskConfig& t : tasks)
      if (t.name == text) throw Error("--task \"" + text + "\" is given twice");
    TaskConfig t = parse_task_shorthand(text, field);
    isos += t.kind == render::TaskKind::isosurface;
    tasks.push_back(std::move(t));
  }
  if (isos < 2) return tasks;
  // Several isosurfaces form one sweep on an "isovalue" axis, so the player can step the isovalue.
  std::vector<TaskConfig> merged;
  std::size_t sweep = SIZE_MAX;  // an index: merged grows, a pointer into it would dangle
  for (TaskConfig& t : tasks) {
    if (t.kind != render::TaskKind::isosurface) {
      merged.push_back(std::move(t));
      continue;
    }
    if (sweep == SIZE_MAX) {
      t.name = "iso";
      t.axis = "isovalue";
      merged.push_back(std::move(t));
      sweep = merged.size() - 1;
      continue;
    }
    for (double v : merged[sweep].isovalues)
      if (v == t.isovalues[0]) throw Error("--task \"" + t.name + "\": the isovalue is given twice");
    merged[sweep].isovalues.push_back(t.isovalues[0]);
  }
  for (const TaskConfig& t : merged)
    if (t.kind != render::TaskKind::isosurface && t.name == "iso")
      throw Error("--task names: \"iso\" is the isovalue sweep's name");
  return merged;
}

std::string task_table_toml(const TaskConfig& t) {
  auto q = [](const std::string& s) {
    std::string out = "\"";
    for (char c : s) out += c == '"' || c == '\\' ? std::string("\\") + c : std::string(1, c);
    return out + "\"";
  };
  auto num = [](double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    std::string text = s.str();
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
    return text;
  };
  // Floats (colours, extinction scales) in their shortest form: 0.85, not 0.85000002384185791.
  auto numf = [](float v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    std::string text(buf, r.ptr);
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
    return text;
  };
  auto list = [&](const std::vector<double>& v) {
    std::string s = "[";
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v[i]);
    return s + "]";
  };
  std::string s = "[[task]]\nname = " + q(t.name) + "\n";
  s += "type = " + q(two_fields(t) ? kVolume2 : render::to_string(t.kind)) + "\n";
  if (t.fields.size() == 1) s += "field = " + q(t.fields[0]) + "\n";
  else s += "fields = [" + q(t.fields.at(0)) + ", " + q(t.fields.at(1)) + "]\n";
  if (!t.axis.empty() && !two_fields(t)) s += "axis_name = " + q(t.axis) + "\n";
  switch (t.kind) {
    case render::TaskKind::volume:
      s += "preset = " + q(t.preset) + "\n";
      if (t.extinction_scale != 1) s += "extinction_scale = " + numf(t.extinction_scale) + "\n";
      s += std::string("relative = ") + (t.windows.at(0).relative ? "true" : "false") + "\n";
      if (t.windows.size() == 1) {
        s += "window = " + list({t.windows[0].lo, t.windows[0].hi}) + "\n";
      } else {
        s += "windows = [";
        for (std::size_t i = 0; i < t.windows.size(); ++i)
          s += (i ? ", " : "") + list({t.windows[i].lo, t.windows[i].hi});
        s += "]\n";
      }
      if (two_fields(t))
        s += "preset2 = " + q(t.preset2) + "\nwindow2 = " + list({t.window2.lo, t.window2.hi}) + "\n";
      break;
    case render::TaskKind::isosurface:
      s += (t.isovalues.size() == 1 ? "isovalue = " + num(t.isovalues[0]) : "isovalues = " + list(t.isovalues)) + "\n";
      s += std::string("relative = ") + (t.iso_relative ? "true" : "false") + "\n";
      s += "colour = [" + numf(t.colour[0]) + ", " + numf(t.colour[1]) + ", " + numf(t.colour[2]) + "]\n";
      break;
    case render::TaskKind::slice:
      s += std::string("axis = \"") + char('x' + t.slice_axis) + "\"\n";
      s += (t.slice_positions.size() == 1 ? "position = " + num(t.slice_positions[0])
                                          : "positions = " + list(t.slice_positions)) + "\n";
      s += "preset = " + q(t.preset) + "\n";
      s += std::string("relative = ") + (t.windows.at(0).relative ? "true" : "false") + "\n";
      s += "window = " + list({t.windows.at(0).lo, t.windows.at(0).hi}) + "\n";
      break;
    case render::TaskKind::mip:
      s += "preset = " + q(t.preset) + "\n";
      s += std::string("relative = ") + (t.windows.at(0).relative ? "true" : "false") + "\n";
      s += "window = " + list({t.windows.at(0).lo, t.windows.at(0).hi}) + "\n";
      break;
  }
  return s;
}

namespace {
// Each kind's words for users, in one place: its --task shorthand and its [[task]] keys (config help).
struct KindHelp {
  const char* shorthand;
  const char* keys;
};
KindHelp kind_help(render::TaskKind k) {
  switch (k) {
    case render::TaskKind::volume:
      return {"volume:PRESET[:LO:HI]",
              "  volume:     preset = \"hot\" (p-wave, s-wave, diverging, grayscale, hot, rainbow); extinction_scale = 1;\n"
              "              window = [lo, hi] (default [0, 1]) or windows = [[lo, hi], ...] (a sweep: one task per window\n"
              "              on axis \"<name> window\"); relative = true (window in multiples of ref) | false (absolute)\n"
              "  volume2:    preset = \"p-wave\", preset2 = \"s-wave\", window = [0, 1], window2 = [0, 1], relative = true,\n"
              "              extinction_scale = 1 (the paper's p-wave orange + s-wave green in one image)\n"};
    case render::TaskKind::isosurface:
      return {"iso:VALUE",
              "  isosurface: isovalue = v or isovalues = [v1, v2, ...] (a sweep on axis \"<name> isovalue\");\n"
              "              relative = false (true: values are fractions of ref); colour = [0.85, 0.85, 0.85]\n"};
    case render::TaskKind::slice:
      return {"slice:x|y|z:FRACTION[:PRESET[:LO:HI]]",
              "  slice:      axis = \"z\" (x, y, z); position = 0.5 or positions = [...] (fractions of the domain; a sweep\n"
              "              on axis \"<name> position\"); preset = \"diverging\"; window = [-1, 1]; relative = true\n"};
    case render::TaskKind::mip:
      return {"mip:PRESET[:LO:HI]",
              "  mip:        maximum-intensity projection (the colour map at the largest value along each ray, of |v|\n"
              "              for the absolute-value presets; opaque); preset = \"hot\"; window = [0, 1] ([-1, 1] for\n"
              "              diverging); relative = true\n"};
  }
  return {"", ""};
}
}  // namespace

std::string task_shorthand_syntax() {
  std::string s;
  for (std::size_t i = 0; i < render::kTaskKinds.size(); ++i)
    s += std::string(i == 0 ? "" : i + 1 == render::kTaskKinds.size() ? " or " : ", ") +
         kind_help(render::kTaskKinds[i]).shorthand;
  return s;
}

std::string task_tables_help() {
  std::string s = "[[task]]    one table per task (or sweep); name (unique, required); type = " +
                  render::task_kind_words(kVolume2) + "; field = \"name\" (volume2: fields = [\"a\", \"b\"])\n";
  for (render::TaskKind k : render::kTaskKinds) s += kind_help(k).keys;
  return s + "  Any sweep may set axis_name to name its axis.\n";
}

}  // namespace panoptes::insitu
