#include "camera/rig_spec.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "camera/number_line.hpp"
#include "camera/volume_rigs.hpp"
#include "core/error.hpp"
#include "core/file_read.hpp"

namespace panoptes::camera {

namespace {

constexpr long long kMaxCamerasPerShell = 10'000'000;  // beyond this a typo is more likely than intent
constexpr long long kMaxCameras = 10'000'000;          // over all shells
constexpr std::size_t kMaxShells = 1000;
const char* const kSyntax =
    "expected yinyang[:NTxNP], latlon[:NLATxNLON[+poles]], fibonacci[:N], file:PATH or the path of an existing "
    "camera file, optionally followed by @R1,R2,... (shell radii in bounding-sphere radii), or lattice:NXxNYxNZ[@MARGIN] "
    "or path:FILE (cameras inside the volume), or inshell[:NRxNP][@F1,F2,...] (rings inside a spherical shell, F in "
    "inscribed radii)";

[[noreturn]] void bad_spec(std::string_view text, const std::string& why) {
  throw Error("rig spec '" + std::string(text) + "': " + why + "; " + kSyntax);
}

int parse_int(std::string_view whole, std::string_view s, const char* what) {
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v < 1)
    bad_spec(whole, std::string(what) + " '" + std::string(s) + "' is not a positive integer");
  return v;
}

double parse_double(std::string_view whole, std::string_view s, const char* what) {
  // std::from_chars for double is available in GCC 12 (Debian 12).
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v))
    bad_spec(whole, std::string(what) + " '" + std::string(s) + "' is not a number");
  return v;
}

void parse_grid(std::string_view whole, std::string_view s, int& rows, int& columns) {
  const auto x = s.find('x');
  if (x == std::string_view::npos) bad_spec(whole, "resolution '" + std::string(s) + "' is not of the form NxM");
  rows = parse_int(whole, s.substr(0, x), "row count");
  columns = parse_int(whole, s.substr(x + 1), "column count");
}

std::string format_double(double v) {
  std::ostringstream os;
  os.precision(12);
  os << v;
  return os.str();
}

}  // namespace

RigSpec RigSpec::parse(std::string_view text) {
  RigSpec spec;
  std::string_view s = text;
  if (s.empty()) bad_spec(text, "empty");
  if (s.starts_with("lattice")) {
    spec.kind = Kind::lattice;
    spec.radii.clear();
    std::string_view rest = s.substr(7);
    if (const auto at = rest.find('@'); at != std::string_view::npos) {
      spec.margin = parse_double(text, rest.substr(at + 1), "lattice margin");
      if (!(spec.margin >= 0 && spec.margin < 0.5))
        bad_spec(text, "lattice margin " + format_double(spec.margin) + " is not in [0, 0.5)");
      rest = rest.substr(0, at);
    }
    if (rest.empty()) return spec;
    if (!rest.starts_with(":") || rest.size() == 1) bad_spec(text, "expected lattice:NXxNYxNZ");
    rest.remove_prefix(1);
    const auto x1 = rest.find('x');
    const auto x2 = x1 == std::string_view::npos ? x1 : rest.find('x', x1 + 1);
    if (x2 == std::string_view::npos) bad_spec(text, "lattice size '" + std::string(rest) + "' is not of the form NXxNYxNZ");
    spec.lattice = {parse_int(text, rest.substr(0, x1), "lattice count"),
                    parse_int(text, rest.substr(x1 + 1, x2 - x1 - 1), "lattice count"),
                    parse_int(text, rest.substr(x2 + 1), "lattice count")};
    const long long plane = 1LL * spec.lattice[0] * spec.lattice[1];  // checked first: the triple product may overflow
    const long long total = plane > kMaxCameras ? plane : plane * spec.lattice[2];
    if (total > kMaxCameras)
      bad_spec(text, std::to_string(total) + " cameras is more than the limit of " + std::to_string(kMaxCameras));
    return spec;
  }
  if (s.starts_with("path:")) {
    spec.kind = Kind::path;
    spec.radii.clear();
    spec.path = std::string(s.substr(5));
    if (spec.path.empty()) bad_spec(text, "no file name after 'path:'");
    return spec;
  }
  const bool shells_prefix = s.starts_with("shells:");
  if (shells_prefix) s.remove_prefix(7);
  if (s.starts_with("file:") ||
      !(s.starts_with("yinyang") || s.starts_with("latlon") || s.starts_with("fibonacci") || s.starts_with("inshell"))) {
    if (shells_prefix) bad_spec(text, "shells need a built-in kind (file rigs carry their own shell indices)");
    spec.kind = Kind::file;
    spec.path = std::string(s.starts_with("file:") ? s.substr(5) : s);
    if (spec.path.empty()) bad_spec(text, "no file name after 'file:'");
    if (!s.starts_with("file:") && !std::filesystem::is_regular_file(spec.path))
      bad_spec(text, spec.path.find_first_of("/.") != std::string::npos ? "no such camera file"
                                                                        : "unknown rig kind and no such file");
    spec.radii.clear();
    return spec;
  }
  // Radii.
  if (const auto at = s.find('@'); at != std::string_view::npos) {
    std::string_view list = s.substr(at + 1);
    s = s.substr(0, at);
    spec.radii.clear();
    while (true) {
      const auto comma = list.find(',');
      spec.radii.push_back(parse_double(text, list.substr(0, comma), "shell radius"));
      if (comma == std::string_view::npos) break;
      list.remove_prefix(comma + 1);
    }
    for (double r : spec.radii)
      if (!(r > 0)) bad_spec(text, "shell radius " + format_double(r) + " is not positive");
  } else if (shells_prefix) {
    bad_spec(text, "'shells:' without '@R1,R2,...'");
  }
  const auto colon = s.find(':');
  const std::string_view kind = s.substr(0, colon);
  const bool has_params = colon != std::string_view::npos;
  const std::string_view params = has_params ? s.substr(colon + 1) : std::string_view{};
  if (has_params && params.empty()) bad_spec(text, "empty parameters after ':'");
  if (kind == "yinyang") {
    spec.kind = Kind::yinyang;
    spec.rows = 5;
    spec.columns = 13;
    if (has_params) parse_grid(text, params, spec.rows, spec.columns);
  } else if (kind == "latlon") {
    spec.kind = Kind::latlon;
    spec.rows = 8;
    spec.columns = 16;
    spec.poles = true;
    if (has_params) {
      std::string_view grid = params;
      spec.poles = grid.ends_with("+poles");
      if (spec.poles) grid.remove_suffix(6);
      parse_grid(text, grid, spec.rows, spec.columns);
    }
  } else if (kind == "inshell") {
    if (shells_prefix) bad_spec(text, "inshell rigs are inside the shell, not on 'shells:' around it");
    spec.kind = Kind::inshell;
    spec.rows = 4;
    spec.columns = 12;
    if (has_params) parse_grid(text, params, spec.rows, spec.columns);
    if (text.find('@') == std::string_view::npos) spec.radii = {kDefaultInShellRadius};
    for (double r : spec.radii)
      if (r > 1) bad_spec(text, "inshell radius " + format_double(r) + " is outside the shell (expected 0 < F <= 1, in inscribed radii)");
  } else if (kind == "fibonacci") {
    spec.kind = Kind::fibonacci;
    spec.count = 130;
    if (has_params) spec.count = parse_int(text, params, "camera count");
  } else {
    // A file whose name starts like a kind (e.g. "yinyang.txt") is still a camera file.
    if (!shells_prefix && std::filesystem::is_regular_file(std::string(text))) {
      spec = RigSpec{};
      spec.kind = Kind::file;
      spec.path = std::string(text);
      spec.radii.clear();
      return spec;
    }
    bad_spec(text, "unknown rig kind '" + std::string(kind) + "'");
  }
  const long long upper = spec.kind == Kind::yinyang ? 2LL * spec.rows * spec.columns : spec.cameras_per_shell();
  if (upper > kMaxCamerasPerShell)
    bad_spec(text, std::to_string(upper) + " cameras per shell is more than the limit of " +
                       std::to_string(kMaxCamerasPerShell));
  if (spec.radii.size() > kMaxShells)
    bad_spec(text, std::to_string(spec.radii.size()) + " shells is more than the limit of " + std::to_string(kMaxShells));
  if (upper * (long long)spec.radii.size() > kMaxCameras)
    bad_spec(text, std::to_string(upper) + " cameras x " + std::to_string(spec.radii.size()) + " shells = " +
                       std::to_string(upper * (long long)spec.radii.size()) + " cameras is more than the limit of " +
                       std::to_string(kMaxCameras));
  return spec;
}

long long RigSpec::cameras_per_shell() const {
  switch (kind) {
    case Kind::yinyang:
      // The overlap rule leaves out a few Yang cameras at some resolutions: count them exactly when cheap.
      return 2LL * rows * columns > kMaxCamerasPerShell ? 2LL * rows * columns
                                                        : (long long)yinyang_pattern(rows, columns).size();
    case Kind::latlon: return 1LL * rows * columns + (poles ? 2 : 0);
    case Kind::inshell: return 1LL * rows * columns;
    case Kind::fibonacci: return count;
    case Kind::file: return 0;
    case Kind::lattice: return 1LL * lattice[0] * lattice[1] * lattice[2];
    case Kind::path: return 0;
  }
  return 0;
}

std::string RigSpec::to_string() const {
  std::string s;
  switch (kind) {
    case Kind::yinyang: s = "yinyang:" + std::to_string(rows) + "x" + std::to_string(columns); break;
    case Kind::latlon:
      s = "latlon:" + std::to_string(rows) + "x" + std::to_string(columns) + (poles ? "+poles" : "");
      break;
    case Kind::fibonacci: s = "fibonacci:" + std::to_string(count); break;
    case Kind::inshell: s = "inshell:" + std::to_string(rows) + "x" + std::to_string(columns); break;
    case Kind::file: return "file:" + path;
    case Kind::path: return "path:" + path;
    case Kind::lattice:
      return "lattice:" + std::to_string(lattice[0]) + "x" + std::to_string(lattice[1]) + "x" +
             std::to_string(lattice[2]) + "@" + format_double(margin);
  }
  s += '@';
  for (std::size_t k = 0; k < radii.size(); ++k) {
    if (k) s += ',';
    s += format_double(radii[k]);
  }
  return s;
}

Rig make_rig(const RigSpec& spec, const Domain& domain) {
  const long long upper =
      spec.kind == RigSpec::Kind::yinyang ? 2LL * spec.rows * spec.columns : spec.cameras_per_shell();
  if (upper > kMaxCamerasPerShell)
    throw Error("rig: " + std::to_string(upper) + " cameras per shell; expected at most " +
                std::to_string(kMaxCamerasPerShell));
  std::vector<PatternPoint> pattern;
  switch (spec.kind) {
    case RigSpec::Kind::yinyang: pattern = yinyang_pattern(spec.rows, spec.columns); break;
    case RigSpec::Kind::latlon: pattern = latlon_pattern(spec.rows, spec.columns, spec.poles); break;
    case RigSpec::Kind::fibonacci: pattern = fibonacci_pattern(spec.count); break;
    case RigSpec::Kind::file: {
      Rig rig = read_rig_file(spec.path, domain, spec.up_axis);
      rig.spec = spec.to_string();
      return rig;
    }
    case RigSpec::Kind::lattice: {
      Rig rig = make_lattice_rig(domain, spec.lattice, spec.margin, spec.fov_y_degrees, spec.up_axis);
      rig.spec = spec.to_string();
      return rig;
    }
    case RigSpec::Kind::inshell: {
      Rig rig = make_shell_interior_rig(domain, spec.rows, spec.columns, spec.radii, spec.fov_y_degrees, spec.up_axis);
      rig.spec = spec.to_string();
      return rig;
    }
    case RigSpec::Kind::path: {
      Rig rig = read_path_rig(spec.path, domain, spec.fov_y_degrees, spec.up_axis);
      rig.spec = spec.to_string();
      return rig;
    }
  }
  Rig rig = place_on_shells(pattern, domain, spec.radii, spec.fov_y_degrees, spec.up, spec.up_axis);
  rig.spec = spec.to_string();
  return rig;
}

Rig make_rig(std::string_view text, const Domain& domain) { return make_rig(RigSpec::parse(text), domain); }

namespace {

struct FileCamera {
  Vec3 position;
  bool has_look_at = false, has_up = false;
  Vec3 look_at, up{0, 0, 1};
  double fov = 0;
  int shell = 0;
  std::string patch = "file";
  std::string where;  // "line 7" / "camera 3", for messages
};

constexpr int kMaxJsonDepth = 16;

// A JSON value for a message, cut short.
std::string shown(const nlohmann::json& j) {
  std::string s = j.dump();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

Vec3 json_vec3(const nlohmann::json& j, const std::string& path, const std::string& where, const char* key) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw FileError(path, where + ": \"" + key + "\" is " + shown(j) + "; expected an array of 3 numbers");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

std::vector<FileCamera> parse_json_cameras(const std::string& text, const std::string& path) {
  nlohmann::json doc;
  try {
    // Bounded nesting: deeper documents are refused while parsing, before a DOM (and the recursive
    // dump() of an error message) could exhaust the stack.
    doc = nlohmann::json::parse(text, [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
      if (depth > kMaxJsonDepth)
        throw FileError(path, "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels; expected a camera list");
      return true;
    });
  } catch (const nlohmann::json::exception& e) {
    throw FileError(path, std::string("not valid JSON (") + e.what() + ")");
  }
  const nlohmann::json* list = &doc;
  if (doc.is_object()) {
    if (!doc.contains("cameras")) throw FileError(path, "no \"cameras\" array; expected {\"cameras\": [...]} or [...]");
    list = &doc["cameras"];
  }
  if (!list->is_array()) throw FileError(path, "\"cameras\" is not an array; expected an array of camera objects");
  std::vector<FileCamera> cams;
  for (std::size_t k = 0; k < list->size(); ++k) {
    const nlohmann::json& c = (*list)[k];
    FileCamera fc;
    fc.where = "camera " + std::to_string(k);
    if (!c.is_object()) throw FileError(path, fc.where + " is " + shown(c) + "; expected an object");
    for (const auto& item : c.items()) {
      const std::string& key = item.key();
      if (key != "position" && key != "look_at" && key != "up" && key != "fov_y_degrees" && key != "shell" &&
          key != "patch")
        throw FileError(path, fc.where + ": unknown key \"" + key +
                                  "\"; expected position, look_at, up, fov_y_degrees, shell, patch");
    }
    if (!c.contains("position")) throw FileError(path, fc.where + ": no \"position\"; expected [x, y, z]");
    fc.position = json_vec3(c["position"], path, fc.where, "position");
    if (c.contains("look_at")) {
      fc.look_at = json_vec3(c["look_at"], path, fc.where, "look_at");
      fc.has_look_at = true;
    }
    if (c.contains("up")) {
      fc.up = json_vec3(c["up"], path, fc.where, "up");
      fc.has_up = true;
    }
    if (c.contains("fov_y_degrees")) {
      if (!c["fov_y_degrees"].is_number())
        throw FileError(path, fc.where + ": \"fov_y_degrees\" is " + shown(c["fov_y_degrees"]) + "; expected a number");
      fc.fov = c["fov_y_degrees"].get<double>();
      if (!(fc.fov > 0 && fc.fov < 180))
        throw FileError(path, fc.where + ": fov_y_degrees " + format_double(fc.fov) + "; expected 0 < fov < 180");
    }
    if (c.contains("shell")) {
      if (!c["shell"].is_number_integer() || c["shell"].get<long long>() < 0 || c["shell"].get<long long>() > 1000000)
        throw FileError(path, fc.where + ": \"shell\" is " + shown(c["shell"]) + "; expected an integer >= 0");
      fc.shell = c["shell"].get<int>();
    }
    if (c.contains("patch")) {
      if (!c["patch"].is_string())
        throw FileError(path, fc.where + ": \"patch\" is " + shown(c["patch"]) + "; expected a string");
      fc.patch = c["patch"].get<std::string>();
    }
    cams.push_back(std::move(fc));
  }
  return cams;
}

std::vector<FileCamera> parse_text_cameras(const std::string& text, const std::string& path) {
  std::vector<FileCamera> cams;
  std::istringstream in(text);
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    FileCamera fc;
    fc.where = "line " + std::to_string(line_no);
    const std::vector<double> v = parse_number_line(line, path, fc.where);
    if (v.empty()) continue;
    if (v.size() != 3 && v.size() != 6 && v.size() != 9 && v.size() != 10 && v.size() != 11)
      throw FileError(path, fc.where + ": " + std::to_string(v.size()) +
                                " numbers; expected x y z [lx ly lz [ux uy uz [fov [shell]]]] (3, 6, 9, 10 or 11)");
    fc.position = {v[0], v[1], v[2]};
    if (v.size() >= 6) {
      fc.look_at = {v[3], v[4], v[5]};
      fc.has_look_at = true;
    }
    if (v.size() >= 9) {
      fc.up = {v[6], v[7], v[8]};
      fc.has_up = true;
    }
    if (v.size() >= 10) {
      fc.fov = v[9];
      if (!(fc.fov > 0 && fc.fov < 180))
        throw FileError(path, fc.where + ": field of view " + format_double(fc.fov) + "; expected 0 < fov < 180");
    }
    if (v.size() >= 11) {
      if (!(v[10] >= 0 && v[10] == std::floor(v[10]) && v[10] <= 1000000))
        throw FileError(path, fc.where + ": shell " + format_double(v[10]) + "; expected an integer >= 0");
      fc.shell = int(v[10]);
    }
    cams.push_back(std::move(fc));
  }
  return cams;
}

}  // namespace

Rig read_rig_file(const std::string& path, const Domain& domain, UpAxis up_axis) {
  const SkyFrame frame = SkyFrame::of(up_axis);
  domain.validate();
  const std::string text = read_regular_file(path, kMaxRigFileBytes, "camera file");
  const auto first = text.find_first_not_of(" \t\r\n");
  const bool json = first != std::string::npos && (text[first] == '{' || text[first] == '[');
  std::vector<FileCamera> cams = json ? parse_json_cameras(text, path) : parse_text_cameras(text, path);
  if (cams.empty()) throw FileError(path, "no cameras; expected at least one");
  if ((long long)cams.size() > kMaxCameras)
    throw FileError(path, std::to_string(cams.size()) + " cameras is more than the limit of " + std::to_string(kMaxCameras));

  Rig rig;
  rig.center = domain.center();
  const double R = domain.radius();
  std::set<int> shells;
  for (const FileCamera& fc : cams) {
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(fc.position[i]) || !std::isfinite(fc.look_at[i]) || !std::isfinite(fc.up[i]))
        throw FileError(path, fc.where + ": a coordinate is not finite");
    RigCamera c;
    c.position = fc.position;
    c.look_at = fc.has_look_at ? fc.look_at : rig.center;
    c.up = fc.has_up ? fc.up : frame.sky;
    if (norm(c.up) == 0) throw FileError(path, fc.where + ": up vector is zero; expected a direction");
    if (!(norm(c.position - c.look_at) > 0))
      throw FileError(path, fc.where + ": position equals the look-at point; expected distinct points");
    c.radius = norm(c.position - rig.center);
    if (!(c.radius > 0)) throw FileError(path, fc.where + ": camera at the domain centre; expected it elsewhere");
    if (fc.fov > 0) {
      c.fov_y_degrees = fc.fov;
    } else {
      const double dc = norm(c.position - rig.center);
      if (!(dc > R))
        throw FileError(path, fc.where + ": camera inside the domain's bounding sphere (distance " + format_double(dc) +
                                  " <= radius " + format_double(R) + ") and no field of view; give fov_y_degrees");
      c.fov_y_degrees = fit_fov_y_degrees(dc, R);
    }
    c.patch = fc.patch;
    sky_latitude_longitude(frame, normalize(c.position - rig.center), c.latitude_deg, c.longitude_deg);
    c.shell = fc.shell;
    shells.insert(fc.shell);
    rig.cameras.push_back(std::move(c));
  }
  rig.shell_count = int(shells.size());
  rig.up_axis = up_axis;
  if (*shells.rbegin() != rig.shell_count - 1)
    throw FileError(path, "shell indices " + std::to_string(*shells.begin()) + ".." + std::to_string(*shells.rbegin()) +
                              " have gaps; expected every shell 0.." + std::to_string(*shells.rbegin()) + " to have a camera");
  rig.spec = "file:" + path;
  return rig;
}

}  // namespace panoptes::camera
