#include "seismic/config_toml.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "core/file_read.hpp"
#include "core/toml_keys.hpp"
#include "seismic/solver.hpp"

namespace panoptes::seismic {

namespace {

using toml_keys::boolean;
using toml_keys::int_in;
using toml_keys::integer;
using toml_keys::only_keys;
using toml_keys::str;

// The source's name for messages and the folder relative paths in it are resolved against.
struct Ctx : toml_keys::Source {
  std::string base;
};

const toml::table* table(const Ctx& c, const toml::table& t, const std::string& key, const std::string& where) {
  const auto* n = t.get(key);
  if (!n) return nullptr;
  if (!n->is_table()) c.fail(where + key, "expected a table");
  return n->as_table();
}

double num(const Ctx& c, const toml::table& t, const std::string& key, const std::string& where, double def,
           bool required = false) {
  const auto* n = t.get(key);
  if (!n) {
    if (required) c.fail(where + key, "missing (a number is required)");
    return def;
  }
  if (auto v = n->value_exact<double>()) return *v;
  if (auto v = n->value_exact<int64_t>()) return double(*v);
  if (auto s = n->value_exact<std::string>(); s && (*s == "inf" || *s == "infinity")) return INFINITY;
  c.fail(where + key, "expected a number");
}

template <std::size_t N>
std::array<double, N> vec(const Ctx& c, const toml::table& t, const std::string& key, const std::string& where,
                          bool required) {
  std::array<double, N> out{};
  const auto* n = t.get(key);
  if (!n) {
    if (required) c.fail(where + key, "missing (an array of " + std::to_string(N) + " numbers is required)");
    return out;
  }
  const auto* a = n->as_array();
  if (!a || a->size() != N) c.fail(where + key, "expected an array of " + std::to_string(N) + " numbers");
  for (std::size_t i = 0; i < N; ++i) {
    const auto& e = *a->get(i);
    if (auto v = e.value_exact<double>()) out[i] = *v;
    else if (auto w = e.value_exact<int64_t>()) out[i] = double(*w);
    else c.fail(where + key, "element " + std::to_string(i) + " is not a number");
  }
  return out;
}

Layer read_layer(const Ctx& c, const toml::table& t, const std::string& w, bool need_top) {
  Layer L;
  L.top = num(c, t, "top", w, 0, need_top);
  L.rho = num(c, t, "rho", w, 0, true);
  L.vp = num(c, t, "vp", w, 0, true);
  L.vs = num(c, t, "vs", w, 0, true);
  L.qp = num(c, t, "qp", w, INFINITY);
  L.qs = num(c, t, "qs", w, INFINITY);
  return L;
}

std::string resolve(const Ctx& c, const std::string& p) {
  if (p.empty() || std::filesystem::path(p).is_absolute()) return p;
  return (std::filesystem::path(c.base) / p).string();
}

SourceTimeFunction read_stf(const Ctx& c, const toml::table& t, const std::string& w) {
  const auto kind = str(c, t, "stf", w, "ricker");
  SourceTimeFunction::Kind k;
  try {
    k = SourceTimeFunction::parse_kind(kind);
  } catch (const Error& e) {
    c.fail(w + "stf", e.what());
  }
  const double delay = num(c, t, "delay", w, -1);
  try {
    if (k == SourceTimeFunction::Kind::ricker) {
      if (t.get("duration")) c.fail(w + "duration", "not used by a ricker source (give frequency)");
      return SourceTimeFunction::ricker(num(c, t, "frequency", w, 0, true), delay);
    }
    if (t.get("frequency")) c.fail(w + "frequency", "not used by kupper/ramp sources (give duration)");
    const double d = num(c, t, "duration", w, 0, true);
    return k == SourceTimeFunction::Kind::kupper ? SourceTimeFunction::kupper(d, std::max(delay, 0.0))
                                                 : SourceTimeFunction::ramp(d, std::max(delay, 0.0));
  } catch (const FileError&) {
    throw;
  } catch (const Error& e) {
    c.fail(w + "stf", e.what());
  }
}

}  // namespace

RunConfig parse_run_config(const std::string& text, const std::string& source_name, const std::string& base_dir) {
  Ctx c{source_name, base_dir};
  toml::table root;
  try {
    root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << "TOML syntax error at line " << e.source().begin.line << ": " << e.description();
    throw FileError(source_name, s.str());
  }
  only_keys(c, root, "", {"grid", "time", "medium", "boundary", "attenuation", "source", "receiver", "receiver_line",
                          "output"});
  RunConfig rc;
  SolverConfig& s = rc.solver;
  const auto* g = table(c, root, "grid", "");
  if (!g) c.fail("grid", "missing table [grid] (nx, ny, nz, h)");
  only_keys(c, *g, "grid", {"nx", "ny", "nz", "h"});
  s.grid.nx = int_in(c, *g, "nx", "grid.", 0, 1, kMaxAxisNodes, true);
  s.grid.ny = int_in(c, *g, "ny", "grid.", 0, 1, kMaxAxisNodes, true);
  s.grid.nz = int_in(c, *g, "nz", "grid.", 0, 1, kMaxAxisNodes, true);
  s.grid.h = num(c, *g, "h", "grid.", 0, true);

  const auto* tm = table(c, root, "time", "");
  if (!tm) c.fail("time", "missing table [time] (steps)");
  only_keys(c, *tm, "time", {"steps", "dt", "courant", "record_every"});
  s.steps = int_in(c, *tm, "steps", "time.", 0, 1, INT_MAX, true);
  s.dt = num(c, *tm, "dt", "time.", 0);
  s.courant = num(c, *tm, "courant", "time.", 0.9);
  s.record_every = int_in(c, *tm, "record_every", "time.", 1, 1, INT_MAX);

  const auto* m = table(c, root, "medium", "");
  if (!m) c.fail("medium", "missing table [medium]");
  const std::string type = str(c, *m, "type", "medium.", "", true);
  if (type == "homogeneous") {
    only_keys(c, *m, "medium", {"type", "rho", "vp", "vs", "qp", "qs"});
    Layer L = read_layer(c, *m, "medium.", false);
    s.medium = MediumSpec::homogeneous(L.rho, L.vp, L.vs, L.qp, L.qs);
  } else if (type == "layered") {
    only_keys(c, *m, "medium", {"type", "layer"});
    const auto* arr = m->get("layer") ? m->get("layer")->as_array() : nullptr;
    if (!arr || arr->empty()) c.fail("medium.layer", "a layered medium needs [[medium.layer]] tables");
    s.medium.kind = MediumSpec::Kind::layered;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const auto* lt = arr->get(i)->as_table();
      const std::string w = "medium.layer[" + std::to_string(i) + "].";
      if (!lt) c.fail(w, "expected a table");
      only_keys(c, *lt, "medium.layer[" + std::to_string(i) + "]", {"top", "rho", "vp", "vs", "qp", "qs"});
      s.medium.layers.push_back(read_layer(c, *lt, w, true));
    }
  } else if (type == "file") {
    only_keys(c, *m, "medium", {"type", "rho_file", "vp_file", "vs_file", "qp_file", "qs_file", "qp", "qs"});
    s.medium.kind = MediumSpec::Kind::file;
    s.medium.rho_file = resolve(c, str(c, *m, "rho_file", "medium.", "", true));
    s.medium.vp_file = resolve(c, str(c, *m, "vp_file", "medium.", "", true));
    s.medium.vs_file = resolve(c, str(c, *m, "vs_file", "medium.", "", true));
    s.medium.qp_file = resolve(c, str(c, *m, "qp_file", "medium.", ""));
    s.medium.qs_file = resolve(c, str(c, *m, "qs_file", "medium.", ""));
    s.medium.qp = num(c, *m, "qp", "medium.", INFINITY);
    s.medium.qs = num(c, *m, "qs", "medium.", INFINITY);
  } else {
    c.fail("medium.type", "'" + type + "' (expected homogeneous, layered or file)");
  }

  if (const auto* b = table(c, root, "boundary", "")) {
    only_keys(c, *b, "boundary", {"free_surface", "pml_cells", "pml_reflection", "pml_frequency"});
    s.boundary.free_surface = boolean(c, *b, "free_surface", "boundary.", true);
    s.boundary.pml_cells = int_in(c, *b, "pml_cells", "boundary.", 10, 0, 100000);
    s.boundary.pml_reflection = num(c, *b, "pml_reflection", "boundary.", 1e-4);
    s.boundary.pml_frequency = num(c, *b, "pml_frequency", "boundary.", 0);
  }
  if (const auto* a = table(c, root, "attenuation", "")) {
    only_keys(c, *a, "attenuation", {"fmin", "fmax", "fref", "mechanisms"});
    s.attenuation.fmin = num(c, *a, "fmin", "attenuation.", 0);
    s.attenuation.fmax = num(c, *a, "fmax", "attenuation.", 0);
    s.attenuation.fref = num(c, *a, "fref", "attenuation.", 0);
    s.attenuation.mechanisms = int_in(c, *a, "mechanisms", "attenuation.", 3, 3, 16);
  }

  if (const auto* n = root.get("source")) {
    const auto* arr = n->as_array();
    if (!arr) c.fail("source", "expected [[source]] tables");
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const auto* st = arr->get(i)->as_table();
      const std::string w = "source[" + std::to_string(i) + "].";
      if (!st) c.fail(w, "expected a table");
      const std::string type = str(c, *st, "type", w, "", true);
      const auto pos = vec<3>(c, *st, "position", w, true);
      const std::set<std::string> common = {"type", "position", "stf", "frequency", "duration", "delay"};
      auto keys = [&](std::set<std::string> extra) {
        extra.insert(common.begin(), common.end());
        only_keys(c, *st, "source[" + std::to_string(i) + "]", extra);
      };
      SourceSpec src;
      if (type == "explosion") {
        keys({"m0"});
        src = SourceSpec::explosion(pos, num(c, *st, "m0", w, 0, true), read_stf(c, *st, w));
      } else if (type == "double_couple") {
        keys({"m0", "strike", "dip", "rake"});
        src = SourceSpec::double_couple(pos, num(c, *st, "strike", w, 0, true), num(c, *st, "dip", w, 0, true),
                                        num(c, *st, "rake", w, 0, true), num(c, *st, "m0", w, 0, true),
                                        read_stf(c, *st, w));
      } else if (type == "moment_tensor") {
        keys({"moment"});
        src = SourceSpec::explosion(pos, 0, read_stf(c, *st, w));
        src.moment = vec<6>(c, *st, "moment", w, true);
      } else if (type == "force") {
        keys({"force"});
        src = SourceSpec::point_force(pos, vec<3>(c, *st, "force", w, true), read_stf(c, *st, w));
      } else {
        c.fail(w + "type", "'" + type + "' (expected explosion, double_couple, moment_tensor or force)");
      }
      s.sources.push_back(src);
    }
  }
  if (s.sources.empty()) c.fail("source", "at least one [[source]] is required");

  if (const auto* n = root.get("receiver")) {
    const auto* arr = n->as_array();
    if (!arr) c.fail("receiver", "expected [[receiver]] tables");
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const auto* rt = arr->get(i)->as_table();
      const std::string w = "receiver[" + std::to_string(i) + "].";
      if (!rt) c.fail(w, "expected a table");
      only_keys(c, *rt, "receiver[" + std::to_string(i) + "]", {"name", "position"});
      s.receivers.push_back(ReceiverSpec{str(c, *rt, "name", w, "", true), vec<3>(c, *rt, "position", w, true)});
    }
  }
  if (const auto* n = root.get("receiver_line")) {
    const auto* arr = n->as_array();
    if (!arr) c.fail("receiver_line", "expected [[receiver_line]] tables");
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const auto* rt = arr->get(i)->as_table();
      const std::string w = "receiver_line[" + std::to_string(i) + "].";
      if (!rt) c.fail(w, "expected a table");
      only_keys(c, *rt, "receiver_line[" + std::to_string(i) + "]", {"name", "start", "end", "count"});
      const std::string name = str(c, *rt, "name", w, "", true);
      const auto a = vec<3>(c, *rt, "start", w, true), b = vec<3>(c, *rt, "end", w, true);
      const long long cnt = integer(c, *rt, "count", w, 0, true);
      if (cnt < 1 || cnt > 100000) c.fail(w + "count", std::to_string(cnt) + " (expected 1 .. 100000)");
      for (long long r = 0; r < cnt; ++r) {
        const double f = cnt == 1 ? 0.0 : double(r) / double(cnt - 1);
        char id[16];
        std::snprintf(id, sizeof id, "_%03lld", r);
        s.receivers.push_back(ReceiverSpec{name + id, {a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]),
                                                        a[2] + f * (b[2] - a[2])}});
      }
    }
  }
  if (const auto* o = table(c, root, "output", "")) {
    only_keys(c, *o, "output", {"directory", "snapshot_fields", "snapshot_every"});
    rc.output_dir = str(c, *o, "directory", "output.", rc.output_dir);
    if (const auto* n = o->get("snapshot_fields")) {
      const auto* arr = n->as_array();
      if (!arr) c.fail("output.snapshot_fields", "expected an array of field names");
      const auto& known = Solver::field_names();
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      for (std::size_t i = 0; i < arr->size(); ++i) {
        const auto v = arr->get(i)->value_exact<std::string>();
        const std::string w = "output.snapshot_fields[" + std::to_string(i) + "]";
        if (!v) c.fail(w, "expected a string (one of " + list + ")");
        if (std::find(known.begin(), known.end(), *v) == known.end())
          c.fail(w, "unknown field '" + *v + "' (expected one of " + list + ")");
        if (std::find(rc.snapshot_fields.begin(), rc.snapshot_fields.end(), *v) == rc.snapshot_fields.end())
          rc.snapshot_fields.push_back(*v);
      }
    }
    const long long every = integer(c, *o, "snapshot_every", "output.", 0);
    if (every < 0 || every > 1000000000) c.fail("output.snapshot_every", std::to_string(every) + " (expected >= 0 steps)");
    rc.snapshot_every = int(every);
  }
  try {
    s.validate();
  } catch (const Error& e) {
    throw FileError(source_name, e.what());
  }
  return rc;
}

RunConfig load_run_config(const std::string& path) {
  const std::string text = read_regular_file(path, 16ull << 20, "configuration file");
  const auto base = std::filesystem::path(path).parent_path().string();
  return parse_run_config(text, path, base.empty() ? "." : base);
}

const char* config_keys_help() {
  return R"(CONFIGURATION (TOML). Coordinates: x = north, y = east, z = depth (positive DOWN), metres;
node (i, j, k) is at (i*h, j*h, k*h); the free surface is z = 0. SI units (kg/m^3, m/s, s, N, N*m).
Unknown keys and wrong types are errors.

[grid]          nx, ny, nz (integers, nodes INCLUDING the absorbing layers), h (spacing, m)
[time]          steps (integer, required); dt (s, default 0 = courant * largest stable step;
                a dt above the CFL limit is an error naming the limit); courant (default 0.9);
                record_every (receiver sampling in steps, default 1)
[medium]        type = "homogeneous" | "layered" | "file"
  homogeneous:  rho, vp, vs (required); qp, qs (default inf = elastic)
  layered:      [[medium.layer]] tables with top (depth of the layer top, m; the first is 0),
                rho, vp, vs, qp, qs; a layer extends down to the next layer's top
  file:         rho_file, vp_file, vs_file (required), qp_file, qs_file (optional), qp, qs
                (uniform Q when no Q file; default inf): .npy float32 '<f4', C order, shape
                (nz, ny, nx) (x fastest); relative paths are relative to the config file
                Checks: rho, vp, vs > 0, vs <= vp/sqrt(2), Q > 0.
[boundary]      free_surface (default true; false = absorbing top, i.e. a whole space);
                pml_cells (CPML thickness in nodes on absorbing faces, default 10);
                pml_reflection (default 1e-4); pml_frequency (Hz, CFS alpha = pi*f; default
                the dominant source frequency)
[attenuation]   used only when some Q is finite: fmin, fmax (constant-Q band, Hz; default
                f_dom/10 .. 10*f_dom), fref (Hz where vp, vs are the phase velocities; default
                f_dom), mechanisms (>= 3, default 3)
[[source]]      type = "explosion" (m0) | "double_couple" (m0, strike, dip, rake in degrees,
                Aki & Richards) | "moment_tensor" (moment = [Mxx, Myy, Mzz, Mxy, Mxz, Myz], N*m)
                | "force" (force = [Fx, Fy, Fz], N); position = [x, y, z] (anywhere in the
                non-absorbing region); stf = "ricker" (frequency = f0 Hz, delay default 1.5/f0;
                S(t) is the moment function M(t)/M0, peak 1) | "kupper" | "ramp" (duration = rise
                time s, delay default 0; S rises from 0 to 1, so M0 is the final moment)
[[receiver]]    name, position = [x, y, z]  -> <output>/<name>.csv (time,vx,vy,vz in m/s)
[[receiver_line]] name, start = [x,y,z], end = [x,y,z], count -> receivers <name>_000 ...
[output]        directory (default "seismic_out"; --out overrides);
                snapshot_fields = ["vz", "phi_p", ...] (default none): fields written as .npy
                float32 of the GLOBAL grid, shape (nz, ny, nx), x fastest, to
                <output>/snapshots/<field>_<step>.npy (step = steps done, 6 digits). Fields: vx, vy,
                vz (m/s), sxx, syy, szz, sxy, sxz, syz (Pa), phi_p = div v, phi_s = |curl v| (1/s);
                each field at its own staggered points, indexed like the nodes (see docs/seismic.md),
                each with a sidecar <field>_<step>.json (grid, origin, spacing, units, time, up_axis
                "z_down") that `panoptes render` reads, so the free surface is on top of its pictures
                snapshot_every (steps, default 0 = only after the last step)
)";
}

}  // namespace panoptes::seismic
