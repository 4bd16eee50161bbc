#include "store/manifest.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <unordered_map>

#include "core/echo.hpp"
#include "core/error.hpp"
#include "store/atomic_file.hpp"
#include "store/bounded_json.hpp"
#include "store/safe_file.hpp"
#include "store/camera_table.hpp"

namespace panoptes::store {

using nlohmann::json;

std::string_view to_string(Status status) {
  switch (status) {
    case Status::running: return "running";
    case Status::complete: return "complete";
    case Status::interrupted: return "interrupted";
  }
  return "unknown";
}

Status parse_status(std::string_view text) {
  if (text == "running") return Status::running;
  if (text == "complete") return Status::complete;
  if (text == "interrupted") return Status::interrupted;
  throw Error("status \"" + echo(text) + "\" is not one of running, complete, interrupted");
}

double Manifest::frame_time(int frame) const {
  return frame >= 0 && std::size_t(frame) < times.size() ? times[std::size_t(frame)] : double(frame);
}

namespace {

void replace_all(std::string& s, std::string_view what, const std::string& with) {
  for (std::size_t pos = 0; (pos = s.find(what, pos)) != std::string::npos; pos += with.size())
    s.replace(pos, what.size(), with);
}

}  // namespace

std::string Manifest::stream_relative_path(int camera, int task) const {
  if (camera < 0 || camera >= camera_count())
    throw Error("camera " + std::to_string(camera) + " out of range (database has " +
                std::to_string(camera_count()) + " cameras)");
  if (task < 0 || task >= task_count())
    throw Error("task " + std::to_string(task) + " out of range (database has " + std::to_string(task_count()) +
                " tasks)");
  std::string s = movie_pattern;
  replace_all(s, "{camera}", std::to_string(camera));
  replace_all(s, "{task}", std::to_string(task));
  return s;
}

int Manifest::find_task(std::string_view name) const {
  for (const auto& t : tasks)
    if (t.name == name) return t.id;
  return -1;
}

int Manifest::find_field(std::string_view name) const {
  for (std::size_t i = 0; i < fields.size(); ++i)
    if (fields[i].name == name) return int(i);
  return -1;
}

int Manifest::find_axis(std::string_view name) const {
  for (std::size_t i = 0; i < axes.size(); ++i)
    if (axes[i].name == name) return int(i);
  return -1;
}

int Manifest::step_task_on_axis(int task, std::string_view axis, int delta) const {
  if (task < 0 || task >= task_count()) return -1;
  const auto& from = tasks[std::size_t(task)].axes;
  int target_index = -1;
  for (const auto& p : from)
    if (p.axis == axis) target_index = p.index + delta;
  if (target_index < 0) return -1;
  for (const auto& t : tasks) {
    if (t.axes.size() != from.size()) continue;
    bool match = true;
    for (std::size_t i = 0; i < from.size() && match; ++i) {
      const auto& a = from[i];
      // Axis positions are compared by name so their order in the two tasks does not matter.
      const auto it = std::find_if(t.axes.begin(), t.axes.end(), [&](const AxisPosition& q) { return q.axis == a.axis; });
      match = it != t.axes.end() && it->index == (a.axis == axis ? target_index : a.index);
    }
    if (match) return t.id;
  }
  return -1;
}

void validate_movie_pattern(const std::string& pattern) {
  const auto bad = [&](const std::string& why) {
    throw Error("movie pattern \"" + echo(pattern) + "\" " + why);
  };
  if (pattern.empty()) bad("is empty");
  if (pattern.find('\0') != std::string::npos) bad("contains a NUL character");
  if (pattern.find('\\') != std::string::npos) bad("contains a backslash");
  if (pattern.front() == '/') bad("is absolute (it must be relative to the database directory)");
  if (pattern.find("{camera}") == std::string::npos) bad("lacks {camera}");
  if (pattern.find("{task}") == std::string::npos) bad("lacks {task}");
  std::string rest = pattern;
  replace_all(rest, "{camera}", "0");
  replace_all(rest, "{task}", "0");
  if (rest.find_first_of("{}") != std::string::npos) bad("has a placeholder other than {camera} and {task}");
  std::size_t start = 0;
  while (true) {
    const std::size_t end = pattern.find('/', start);
    const std::string part = pattern.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (part.empty()) bad("has an empty path component");
    if (part == "..") bad("reaches outside the database directory (\"..\")");
    if (part == ".") bad("has a \".\" path component");
    if (end == std::string::npos) break;
    start = end + 1;
  }
  if (rest == "panoptes.json" || rest.rfind(".panoptes", 0) == 0) bad("would overwrite the manifest or lock");
}

void Manifest::validate() const {
  const auto fail = [](const std::string& m) { throw Error("manifest: " + m); };
  if (schema_version < kOldestSchemaVersion || schema_version > kSchemaVersion)
    fail("schema_version " + std::to_string(schema_version) + " is not supported (this build reads versions " +
         std::to_string(kOldestSchemaVersion) + " to " + std::to_string(kSchemaVersion) + ")");
  if (image.width <= 0 || image.height <= 0)
    fail("image size " + std::to_string(image.width) + "x" + std::to_string(image.height) + " must be positive");
  if (image.width > kMaxImageSide || image.height > kMaxImageSide ||
      std::int64_t(image.width) * image.height > kMaxImagePixels)
    fail("image size " + std::to_string(image.width) + "x" + std::to_string(image.height) +
         " is larger than H.264 allows (at most " + std::to_string(kMaxImageSide) + " per side and " +
         std::to_string(kMaxImagePixels) + " pixels, e.g. 8192x4352)");
  if (image.padded_width > kMaxImageSide + 1 || image.padded_height > kMaxImageSide + 1)
    fail("padded image size " + std::to_string(image.padded_width) + "x" + std::to_string(image.padded_height) +
         " is larger than " + std::to_string(kMaxImageSide) + " per side");
  if (std::int64_t(cameras.size()) > kMaxCameras)
    fail(std::to_string(cameras.size()) + " cameras, more than the limit of " + std::to_string(kMaxCameras));
  if (image.padded_width != 0 || image.padded_height != 0)
    if (image.padded_width < image.width || image.padded_height < image.height)
      fail("padded image size " + std::to_string(image.padded_width) + "x" + std::to_string(image.padded_height) +
           " is smaller than the image size " + std::to_string(image.width) + "x" + std::to_string(image.height));
  if (!domain.up_axis.empty() && domain.up_axis != "z_up" && domain.up_axis != "z_down")
    fail("domain.up_axis \"" + echo(domain.up_axis) + "\"; expected \"z_up\" or \"z_down\"");
  if (frame_checks.recorded()) {
    if (frame_checks.scheme != kFrameCheckScheme && frame_checks.scheme != kFrameCheckSchemeUnboundHeader)
      fail("frame_checks.scheme \"" + echo(frame_checks.scheme) + "\" is not known to this build (expected \"" +
           kFrameCheckScheme + "\" or \"" + kFrameCheckSchemeUnboundHeader + "\")");
    const auto& id = frame_checks.database_id;
    if (id.size() != 16 || id.find_first_not_of("0123456789abcdef") != std::string::npos)
      fail("frame_checks.database_id \"" + echo(id) + "\" is not 16 lowercase hex digits");
  }
  if (!(playback_fps == 0 || (std::isfinite(playback_fps) && playback_fps > 0 && playback_fps <= 1000)))
    fail("playback_fps " + std::to_string(playback_fps) + "; expected 0 (none) or a rate in (0, 1000] frames per second");
  try {
    video.validate();
  } catch (const Error& e) {
    fail(e.what());  // VideoSettings::validate() already names "video settings"
  }
  try {
    validate_movie_pattern(movie_pattern);
  } catch (const Error& e) {
    fail(e.what());
  }
  if (frames_written < 0) fail("frames_written " + std::to_string(frames_written) + " is negative");
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const auto& c = cameras[i];
    // The message is built only on failure: this loop runs over 10^5-10^6 cameras at every checkpoint.
    const auto at = [i] { return "cameras[" + std::to_string(i) + "]"; };
    if (c.id != int(i)) fail(at() + ".id is " + std::to_string(c.id) + ", expected its index " + std::to_string(i));
    if (!(c.fov_y_deg > 0 && c.fov_y_deg < 180))
      fail(at() + ".fov_y_deg " + std::to_string(c.fov_y_deg) + " is not in (0, 180)");
    if (c.position == c.look_at) fail(at() + ": position equals look_at");
  }
  if (!graph.neighbours.empty()) {
    if (graph.neighbours.size() != cameras.size())
      fail("navigation graph has " + std::to_string(graph.neighbours.size()) + " entries, expected 0 or one per camera (" +
           std::to_string(cameras.size()) + ")");
    const int n = camera_count();
    for (std::size_t i = 0; i < graph.neighbours.size(); ++i) {
      const auto& g = graph.neighbours[i];
      for (int v : {g.left, g.right, g.up, g.down, g.in, g.out})
        if (v < -1 || v >= n)
          fail("navigation graph entry " + std::to_string(i) + " names camera " + std::to_string(v) +
               " (valid: -1 or 0.." + std::to_string(n - 1) + ")");
    }
  }
  if (time_units.size() > 64) fail("time_units is " + std::to_string(time_units.size()) + " characters; expected a unit of at most 64");
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const auto at = [i] { return "fields[" + std::to_string(i) + "]"; };
    if (fields[i].name.empty()) fail(at() + " has an empty name");
    if (find_field(fields[i].name) != int(i)) fail(at() + ": the name \"" + fields[i].name + "\" is used twice");
    for (std::size_t f = 0; f < fields[i].references.size(); ++f)
      if (!(std::isfinite(fields[i].references[f]) && fields[i].references[f] > 0))
        fail(at() + ".references[" + std::to_string(f) + "] is " + std::to_string(fields[i].references[f]) +
             "; expected a finite value > 0");
  }
  std::unordered_map<std::string, std::size_t> axis_size;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    if (axes[i].name.empty()) fail("axes[" + std::to_string(i) + "] has an empty name");
    if (!axis_size.emplace(axes[i].name, axes[i].values.size()).second)
      fail("axis \"" + echo(axes[i].name) + "\" is defined twice");
  }
  std::set<std::string_view> names;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const auto& t = tasks[i];
    const std::string at = "tasks[" + std::to_string(i) + "]";
    if (t.id != int(i)) fail(at + ".id is " + std::to_string(t.id) + ", expected its index " + std::to_string(i));
    if (t.name.empty()) fail(at + " has an empty name");
    if (!names.insert(t.name).second) fail("task name \"" + echo(t.name) + "\" is used twice");
    if (!t.parameters.is_object()) fail(at + ".parameters is not a JSON object");
    for (const auto& p : t.axes) {
      const auto it = axis_size.find(p.axis);
      if (it == axis_size.end()) fail(at + " sits on unknown axis \"" + echo(p.axis) + "\"");
      if (p.index < 0 || std::size_t(p.index) >= it->second)
        fail(at + " has index " + std::to_string(p.index) + " on axis \"" + echo(p.axis) + "\" of " +
             std::to_string(it->second) + " values");
    }
  }
  if (!rig.parameters.is_object()) fail("rig.parameters is not a JSON object");
}

// ---- JSON ------------------------------------------------------------------------------------

namespace {

json vec3_json(const Vec3& v) { return json::array({v.x, v.y, v.z}); }

json labels_json(const std::map<std::string, std::string>& m) {
  json j = json::object();
  for (const auto& [k, v] : m) j[k] = v;
  return j;
}

// Field access with messages naming the JSON path and the expected type.
struct Reader {
  const std::string& source;

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw Error(source + ": " + path + ": " + what);
  }
  const json& field(const json& obj, const char* key, const std::string& path) const {
    if (!obj.is_object()) fail(path, "expected a JSON object");
    const auto it = obj.find(key);
    if (it == obj.end()) fail(path.empty() ? std::string(key) : path + "." + key, "missing");
    return *it;
  }
  const json* optional(const json& obj, const char* key, const std::string& path) const {
    if (!obj.is_object()) fail(path, "expected a JSON object");
    const auto it = obj.find(key);
    return it == obj.end() || it->is_null() ? nullptr : &*it;
  }
  std::string str(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, "expected a string, found " + std::string(j.type_name()));
    return j.get<std::string>();
  }
  double num(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "expected a number, found " + std::string(j.type_name()));
    return j.get<double>();
  }
  std::int64_t integer(const json& j, const std::string& path) const {
    if (!j.is_number_integer()) fail(path, "expected an integer, found " + std::string(j.type_name()));
    return j.get<std::int64_t>();
  }
  int int32(const json& j, const std::string& path) const {
    const std::int64_t v = integer(j, path);
    if (v < INT32_MIN || v > INT32_MAX) fail(path, "integer " + std::to_string(v) + " out of range");
    return int(v);
  }
  const json& array(const json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, "expected an array, found " + std::string(j.type_name()));
    return j;
  }
  Vec3 vec3(const json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != 3) fail(path, "expected an array of 3 numbers");
    return {num(j[0], path + "[0]"), num(j[1], path + "[1]"), num(j[2], path + "[2]")};
  }
  std::map<std::string, std::string> string_map(const json& j, const std::string& path) const {
    if (!j.is_object()) fail(path, "expected an object of strings");
    std::map<std::string, std::string> m;
    for (auto it = j.begin(); it != j.end(); ++it) m[it.key()] = str(it.value(), path + "." + it.key());
    return m;
  }
  std::string opt_str(const json& obj, const char* key, const std::string& path) const {
    const json* j = optional(obj, key, path);
    return j ? str(*j, path + "." + key) : std::string();
  }
};

}  // namespace

namespace {

// The manifest as JSON: with `table`, the cameras and the graph are replaced by a reference to it.
json manifest_json(const Manifest& m, const CameraTableRef* table) {
  json j;
  // Always the current version: both forms (inline cameras or a table) are valid in it, and a manifest
  // read from a version-1 file is written back as version 2.
  j["schema_version"] = kSchemaVersion;
  j["format"] = "panoptes movie database";
  j["title"] = m.title;
  j["status"] = std::string(to_string(m.status));
  j["frames_written"] = m.frames_written;
  j["movie_pattern"] = m.movie_pattern;
  j["provenance"] = {{"program", m.provenance.program},
                     {"version", m.provenance.version},
                     {"created", m.provenance.created},
                     {"host", m.provenance.host},
                     {"command_line", m.provenance.command_line},
                     {"extra", labels_json(m.provenance.extra)}};
  j["domain"] = {{"dims", m.domain.dims},
                 {"origin", vec3_json(m.domain.origin)},
                 {"spacing", vec3_json(m.domain.spacing)},
                 {"units", m.domain.units}};
  if (!m.domain.up_axis.empty()) j["domain"]["up_axis"] = m.domain.up_axis;
  if (!m.domain.grid.empty()) j["domain"]["grid"] = m.domain.grid;
  if (m.playback_fps > 0) j["playback_fps"] = m.playback_fps;
  if (m.frame_checks.recorded())
    j["frame_checks"] = {{"scheme", m.frame_checks.scheme}, {"database_id", m.frame_checks.database_id}};
  j["times"] = m.times;
  // Additive (issue 34): older readers ignore them, and manifests without them stay readable.
  if (!m.time_units.empty()) j["time_units"] = m.time_units;
  if (!m.fields.empty()) {
    json fields = json::array();
    for (const auto& f : m.fields) {
      json e = {{"name", f.name}, {"units", f.units}, {"references", f.references}};
      if (!f.reference_mode.empty()) e["reference_mode"] = f.reference_mode;
      fields.push_back(std::move(e));
    }
    j["fields"] = std::move(fields);
  }
  j["image"] = {{"width", m.image.width},
                {"height", m.image.height},
                {"padded_width", m.image.padded_width},
                {"padded_height", m.image.padded_height}};
  j["video"] = {{"codec", "h264"},
                {"container", "fragmented mp4"},
                {"crf", m.video.crf},
                {"preset", m.video.preset},
                {"gop", m.video.gop},
                {"threads", m.video.threads},
                {"fps", m.video.fps}};
  j["rig"] = {{"kind", m.rig.kind}, {"parameters", m.rig.parameters}};
  const json columns = json::array({"left", "right", "up", "down", "in", "out"});
  if (table) {
    j["camera_table"] = {{"file", table->file},
                         {"format", "panoptes camera table " + std::to_string(kCameraTableVersion)},
                         {"bytes", table->bytes},
                         {"crc32", table->crc32},
                         {"cameras", table->cameras},
                         {"navigation", table->navigation}};
    j["navigation"] = {{"columns", columns}};
  } else {
  json cams = json::array();
  for (const auto& c : m.cameras) {
    json labels = {{"patch", c.labels.patch}, {"lat_deg", c.labels.lat_deg}, {"lon_deg", c.labels.lon_deg},
                   {"shell", c.labels.shell}};
    if (!c.labels.extra.empty()) labels["extra"] = labels_json(c.labels.extra);
    cams.push_back({{"id", c.id},
                    {"position", vec3_json(c.position)},
                    {"look_at", vec3_json(c.look_at)},
                    {"up", vec3_json(c.up)},
                    {"fov_y_deg", c.fov_y_deg},
                    {"labels", std::move(labels)}});
  }
  j["cameras"] = std::move(cams);
  // One compact row per camera keeps the graph small for 10^5 cameras.
  json rows = json::array();
  for (const auto& g : m.graph.neighbours) rows.push_back(json::array({g.left, g.right, g.up, g.down, g.in, g.out}));
  j["navigation"] = {{"columns", columns}, {"neighbours", std::move(rows)}};
  }
  json axes = json::array();
  for (const auto& a : m.axes) axes.push_back({{"name", a.name}, {"values", a.values}, {"units", a.units}});
  j["axes"] = std::move(axes);
  json tasks = json::array();
  for (const auto& t : m.tasks) {
    json pos = json::array();
    for (const auto& p : t.axes) pos.push_back({{"axis", p.axis}, {"index", p.index}});
    tasks.push_back({{"id", t.id},
                     {"name", t.name},
                     {"method", t.method},
                     {"fields", t.fields},
                     {"parameters", t.parameters},
                     {"axes", std::move(pos)}});
  }
  j["tasks"] = std::move(tasks);
  return j;
}

}  // namespace

json to_json(const Manifest& m) { return manifest_json(m, nullptr); }

Manifest manifest_from_json(const json& j, const std::string& source, const std::filesystem::path& dir) {
  const Reader r{source};
  if (!j.is_object()) r.fail("manifest", "expected a JSON object at the top level");
  Manifest m;
  {
    const auto it = j.find("schema_version");
    if (it == j.end()) r.fail("schema_version", "missing (not a Panoptes manifest?)");
    const std::int64_t v = r.integer(*it, "schema_version");
    if (v < kOldestSchemaVersion || v > kSchemaVersion)
      throw Error(source + ": schema_version " + std::to_string(v) + " is not supported (this build reads versions " +
                  std::to_string(kOldestSchemaVersion) + " to " + std::to_string(kSchemaVersion) + "; " +
                  (v > kSchemaVersion ? "written by a newer Panoptes" : "unknown version") + ")");
    m.schema_version = int(v);
  }
  m.title = r.opt_str(j, "title", "");
  m.status = [&] {
    const std::string s = r.str(r.field(j, "status", ""), "status");
    try {
      return parse_status(s);
    } catch (const Error& e) {
      r.fail("status", e.what());
    }
  }();
  m.frames_written = r.int32(r.field(j, "frames_written", ""), "frames_written");
  m.movie_pattern = r.str(r.field(j, "movie_pattern", ""), "movie_pattern");

  if (const json* p = r.optional(j, "provenance", "")) {
    m.provenance.program = r.opt_str(*p, "program", "provenance");
    m.provenance.version = r.opt_str(*p, "version", "provenance");
    m.provenance.created = r.opt_str(*p, "created", "provenance");
    m.provenance.host = r.opt_str(*p, "host", "provenance");
    m.provenance.command_line = r.opt_str(*p, "command_line", "provenance");
    if (const json* e = r.optional(*p, "extra", "provenance")) m.provenance.extra = r.string_map(*e, "provenance.extra");
  }
  if (const json* d = r.optional(j, "domain", "")) {
    if (const json* dims = r.optional(*d, "dims", "domain")) {
      if (!dims->is_array() || dims->size() != 3) r.fail("domain.dims", "expected an array of 3 integers");
      for (int i = 0; i < 3; ++i) m.domain.dims[std::size_t(i)] = r.integer((*dims)[std::size_t(i)], "domain.dims");
    }
    if (const json* o = r.optional(*d, "origin", "domain")) m.domain.origin = r.vec3(*o, "domain.origin");
    if (const json* s = r.optional(*d, "spacing", "domain")) m.domain.spacing = r.vec3(*s, "domain.spacing");
    m.domain.units = r.opt_str(*d, "units", "domain");
    m.domain.up_axis = r.opt_str(*d, "up_axis", "domain");
    m.domain.grid = r.opt_str(*d, "grid", "domain");
  }
  if (const json* v = r.optional(j, "playback_fps", "")) m.playback_fps = r.num(*v, "playback_fps");
  if (const json* fc = r.optional(j, "frame_checks", "")) {
    m.frame_checks.scheme = r.str(r.field(*fc, "scheme", "frame_checks"), "frame_checks.scheme");
    m.frame_checks.database_id = r.str(r.field(*fc, "database_id", "frame_checks"), "frame_checks.database_id");
  }
  if (const json* t = r.optional(j, "times", "")) {
    r.array(*t, "times");
    m.times.reserve(t->size());
    for (std::size_t i = 0; i < t->size(); ++i) m.times.push_back(r.num((*t)[i], "times[" + std::to_string(i) + "]"));
  }
  m.time_units = r.opt_str(j, "time_units", "");
  if (const json* fs = r.optional(j, "fields", "")) {
    r.array(*fs, "fields");
    for (std::size_t i = 0; i < fs->size(); ++i) {
      const std::string at = "fields[" + std::to_string(i) + "]";
      const json& f = (*fs)[i];
      FieldInfo info;
      info.name = r.str(r.field(f, "name", at), at + ".name");
      info.units = r.opt_str(f, "units", at);
      info.reference_mode = r.opt_str(f, "reference_mode", at);
      if (!info.reference_mode.empty() && info.reference_mode != "snapshot" && info.reference_mode != "running" &&
          info.reference_mode != "fixed")
        r.fail(at + ".reference_mode", "\"" + info.reference_mode + "\"; expected \"snapshot\", \"running\" or \"fixed\"");
      if (const json* refs = r.optional(f, "references", at)) {
        r.array(*refs, at + ".references");
        info.references.reserve(refs->size());
        for (std::size_t k = 0; k < refs->size(); ++k)
          info.references.push_back(r.num((*refs)[k], at + ".references[" + std::to_string(k) + "]"));
      }
      m.fields.push_back(std::move(info));
    }
  }
  {
    const json& im = r.field(j, "image", "");
    m.image.width = r.int32(r.field(im, "width", "image"), "image.width");
    m.image.height = r.int32(r.field(im, "height", "image"), "image.height");
    if (const json* v = r.optional(im, "padded_width", "image")) m.image.padded_width = r.int32(*v, "image.padded_width");
    if (const json* v = r.optional(im, "padded_height", "image")) m.image.padded_height = r.int32(*v, "image.padded_height");
  }
  if (const json* v = r.optional(j, "video", "")) {
    if (const json* x = r.optional(*v, "codec", "video"); x && r.str(*x, "video.codec") != "h264")
      r.fail("video.codec", "\"" + x->get<std::string>() + "\" is not supported (expected \"h264\")");
    if (const json* x = r.optional(*v, "crf", "video")) m.video.crf = r.int32(*x, "video.crf");
    if (const json* x = r.optional(*v, "preset", "video")) m.video.preset = r.str(*x, "video.preset");
    if (const json* x = r.optional(*v, "gop", "video")) m.video.gop = r.int32(*x, "video.gop");
    if (const json* x = r.optional(*v, "threads", "video")) m.video.threads = r.int32(*x, "video.threads");
    if (const json* x = r.optional(*v, "fps", "video")) m.video.fps = r.num(*x, "video.fps");
  }
  if (const json* rig = r.optional(j, "rig", "")) {
    m.rig.kind = r.opt_str(*rig, "kind", "rig");
    if (const json* p = r.optional(*rig, "parameters", "rig")) {
      if (!p->is_object()) r.fail("rig.parameters", "expected a JSON object");
      m.rig.parameters = *p;
    }
  }
  // Schema 2: the cameras and the graph are in the binary camera table (read after the JSON checks);
  // inline cameras as in schema 1 are still accepted (hand-written and old manifests).
  std::optional<CameraTableRef> table;
  if (const json* t = r.optional(j, "camera_table", "")) {
    if (m.schema_version < 2) r.fail("camera_table", "is not part of schema_version 1");
    if (j.contains("cameras")) r.fail("cameras", "present although the cameras are in camera_table (one or the other)");
    CameraTableRef ref;
    ref.file = r.str(r.field(*t, "file", "camera_table"), "camera_table.file");
    try {
      validate_camera_table_name(ref.file);
    } catch (const Error& e) {
      r.fail("camera_table.file", e.what());
    }
    const std::int64_t bytes = r.integer(r.field(*t, "bytes", "camera_table"), "camera_table.bytes");
    const std::int64_t crc = r.integer(r.field(*t, "crc32", "camera_table"), "camera_table.crc32");
    ref.cameras = r.integer(r.field(*t, "cameras", "camera_table"), "camera_table.cameras");
    if (bytes < 0) r.fail("camera_table.bytes", std::to_string(bytes) + " is negative");
    if (crc < 0 || crc > INT64_C(0xFFFFFFFF)) r.fail("camera_table.crc32", std::to_string(crc) + " is not a 32-bit value");
    if (ref.cameras < 0 || ref.cameras > kMaxCameras)
      r.fail("camera_table.cameras", std::to_string(ref.cameras) + " is out of range (0.." + std::to_string(kMaxCameras) +
                                         " cameras; readers keep each camera in memory)");
    ref.bytes = std::uint64_t(bytes);
    ref.crc32 = std::uint32_t(crc);
    if (const json* nav = r.optional(*t, "navigation", "camera_table")) {
      if (!nav->is_boolean()) r.fail("camera_table.navigation", "expected true or false");
      ref.navigation = nav->get<bool>();
    }
    if (dir.empty()) r.fail("camera_table", "refers to the file " + ref.file + ", but no database directory was given");
    table = ref;
  } else {
    const json& cams = r.array(r.field(j, "cameras", ""), "cameras");
    if (std::int64_t(cams.size()) > kMaxCameras)
      r.fail("cameras", std::to_string(cams.size()) + " cameras, more than the limit of " + std::to_string(kMaxCameras));
    m.cameras.resize(cams.size());
    for (std::size_t i = 0; i < cams.size(); ++i) {
      const json& c = cams[i];
      const std::string at = "cameras[" + std::to_string(i) + "]";
      auto& e = m.cameras[i];
      e.id = r.int32(r.field(c, "id", at), at + ".id");
      e.position = r.vec3(r.field(c, "position", at), at + ".position");
      e.look_at = r.vec3(r.field(c, "look_at", at), at + ".look_at");
      e.up = r.vec3(r.field(c, "up", at), at + ".up");
      e.fov_y_deg = r.num(r.field(c, "fov_y_deg", at), at + ".fov_y_deg");
      if (const json* l = r.optional(c, "labels", at)) {
        const std::string lat = at + ".labels";
        e.labels.patch = r.opt_str(*l, "patch", lat);
        if (const json* x = r.optional(*l, "lat_deg", lat)) e.labels.lat_deg = r.num(*x, lat + ".lat_deg");
        if (const json* x = r.optional(*l, "lon_deg", lat)) e.labels.lon_deg = r.num(*x, lat + ".lon_deg");
        if (const json* x = r.optional(*l, "shell", lat)) e.labels.shell = r.int32(*x, lat + ".shell");
        if (const json* x = r.optional(*l, "extra", lat)) e.labels.extra = r.string_map(*x, lat + ".extra");
      }
    }
  }
  if (const json* nav = r.optional(j, "navigation", "")) {
    static const char* kColumns[] = {"left", "right", "up", "down", "in", "out"};
    if (const json* cols = r.optional(*nav, "columns", "navigation")) {
      if (!cols->is_array() || cols->size() != 6) r.fail("navigation.columns", "expected [left,right,up,down,in,out]");
      for (std::size_t k = 0; k < 6; ++k)
        if ((*cols)[k] != kColumns[k]) r.fail("navigation.columns", "expected [left,right,up,down,in,out]");
    }
    if (const json* rows = r.optional(*nav, "neighbours", "navigation")) {
      if (table) r.fail("navigation.neighbours", "present although the graph is in camera_table (one or the other)");
      r.array(*rows, "navigation.neighbours");
      m.graph.neighbours.resize(rows->size());
      for (std::size_t i = 0; i < rows->size(); ++i) {
        const json& row = (*rows)[i];
        const std::string at = "navigation.neighbours[" + std::to_string(i) + "]";
        if (!row.is_array() || row.size() != 6) r.fail(at, "expected an array of 6 camera ids");
        auto& g = m.graph.neighbours[i];
        int* slots[] = {&g.left, &g.right, &g.up, &g.down, &g.in, &g.out};
        for (std::size_t k = 0; k < 6; ++k) *slots[k] = r.int32(row[k], at);
      }
    }
  }
  if (const json* axes = r.optional(j, "axes", "")) {
    r.array(*axes, "axes");
    for (std::size_t i = 0; i < axes->size(); ++i) {
      const std::string at = "axes[" + std::to_string(i) + "]";
      const json& a = (*axes)[i];
      ParameterAxis axis;
      axis.name = r.str(r.field(a, "name", at), at + ".name");
      const json& values = r.array(r.field(a, "values", at), at + ".values");
      for (std::size_t k = 0; k < values.size(); ++k) axis.values.push_back(r.num(values[k], at + ".values"));
      axis.units = r.opt_str(a, "units", at);
      m.axes.push_back(std::move(axis));
    }
  }
  {
    const json& tasks = r.array(r.field(j, "tasks", ""), "tasks");
    m.tasks.resize(tasks.size());
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      const json& t = tasks[i];
      const std::string at = "tasks[" + std::to_string(i) + "]";
      auto& e = m.tasks[i];
      e.id = r.int32(r.field(t, "id", at), at + ".id");
      e.name = r.str(r.field(t, "name", at), at + ".name");
      e.method = r.opt_str(t, "method", at);
      if (const json* f = r.optional(t, "fields", at)) {
        r.array(*f, at + ".fields");
        for (const auto& x : *f) e.fields.push_back(r.str(x, at + ".fields"));
      }
      if (const json* p = r.optional(t, "parameters", at)) {
        if (!p->is_object()) r.fail(at + ".parameters", "expected a JSON object");
        e.parameters = *p;
      }
      if (const json* pos = r.optional(t, "axes", at)) {
        r.array(*pos, at + ".axes");
        for (const auto& p : *pos)
          e.axes.push_back({r.str(r.field(p, "axis", at + ".axes"), at + ".axes.axis"),
                            r.int32(r.field(p, "index", at + ".axes"), at + ".axes.index")});
      }
    }
  }
  if (table) {
    read_camera_table(dir, *table, m);
    if (m.graph.empty() == table->navigation)
      throw FileError((dir / table->file).string(), std::string("camera table ") +
                                                        (table->navigation ? "lacks" : "holds") +
                                                        " a navigation graph, the manifest says the opposite");
  }
  try {
    m.validate();
  } catch (const Error& e) {
    throw Error(source + ": " + e.what());
  }
  return m;
}

namespace {

// Reads and parses a manifest file's JSON: never through a link, never from a FIFO or device, at most
// kMaxManifestBytes, bounded nesting (see safe_file.hpp, bounded_json.hpp). Throws FileError.
json read_manifest_json(const std::filesystem::path& path) {
  const std::string name = path.string();
  const auto [dir, file] = split_parent(path);
  const FileHandle dfd = open_directory(dir);
  const FileHandle fd = open_regular_file(dfd.get(), file, kMaxManifestBytes, "manifest", dir, true);
  if (!fd) throw FileError(name, "no manifest here (not a Panoptes database)");
  const std::string text = read_regular_file(dfd.get(), file, kMaxManifestBytes, "manifest", dir);
  return parse_bounded_json(text, name, {}, "manifest");
}

}  // namespace

Manifest read_manifest(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  for (int attempt = 0;; ++attempt) {
    const json j = read_manifest_json(path);
    try {
      return manifest_from_json(j, name, dir);
    } catch (const FileError& e) {
      // A writer that replaced the cameras renames the new manifest into place and then removes the old
      // table: a reader between the two reads an old manifest whose table is gone. Read once more.
      const json* t = j.is_object() && j.contains("camera_table") ? &j["camera_table"] : nullptr;
      std::error_code ec;
      if (attempt == 0 && t && t->is_object() && t->contains("file") && (*t)["file"].is_string() &&
          !std::filesystem::exists(dir / (*t)["file"].get<std::string>(), ec))
        continue;
      throw;
    } catch (const Error& e) {
      // Messages already start with the file name.
      throw FileError(name, std::string(e.what()).substr(name.size() + 2));
    }
  }
}

std::string referenced_camera_table(const std::filesystem::path& manifest_path) {
  try {
    const json j = read_manifest_json(manifest_path);
    const std::string file = j.at("camera_table").at("file").get<std::string>();
    validate_camera_table_name(file);
    return file;
  } catch (const std::exception&) {
    return {};
  }
}

namespace {

// Readable yet compact text: one top-level field per line, and the long lists (cameras, tasks, graph
// rows) one compact element per line. Fully indented JSON would be twice as large and slower to parse
// (a 10^4-camera manifest: 4.2 MB indented).
std::string manifest_text(const json& j) {
  std::string out = "{\n";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!first) out += ",\n";
    first = false;
    out += ' ';
    out += json(it.key()).dump();
    out += ": ";
    const json& v = it.value();
    const json* list = &v;
    std::string suffix;
    if (v.is_object() && v.contains("neighbours")) {  // navigation: {columns, neighbours: [rows]}
      out += "{\"columns\": " + v.at("columns").dump() + ", \"neighbours\": ";
      list = &v.at("neighbours");
      suffix = "}";
    }
    if (list->is_array() && !list->empty() && (list->front().is_object() || list->front().is_array())) {
      out += "[\n";
      for (std::size_t i = 0; i < list->size(); ++i) out += "  " + (*list)[i].dump() + (i + 1 < list->size() ? ",\n" : "\n");
      out += " ]";
    } else {
      out += list->dump();
    }
    out += suffix;
  }
  return out + "\n}\n";
}

}  // namespace

void write_manifest_atomic(const std::filesystem::path& path, const Manifest& manifest, const CameraTableRef& table) {
  manifest.validate();
  if (table.cameras != manifest.camera_count() || table.navigation == manifest.graph.empty())
    throw Error(path.string() + ": the camera table " + table.file + " holds " + std::to_string(table.cameras) +
                " cameras" + (table.navigation ? " and a graph" : "") + ", the manifest has " +
                std::to_string(manifest.camera_count()) + (manifest.graph.empty() ? "" : " and a graph"));
  write_file_atomic(path, manifest_text(manifest_json(manifest, &table)), "manifest");
}

void write_manifest_atomic(const std::filesystem::path& path, const Manifest& manifest) {
  manifest.validate();
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  const std::string previous = referenced_camera_table(path);
  // Table first: its name is content-addressed, so the manifest on disk stays valid until the rename.
  const CameraTableRef table = write_camera_table(dir, manifest);
  try {
    write_manifest_atomic(path, manifest, table);
  } catch (...) {
    if (table.file != previous) ::unlink((dir / table.file).c_str());  // nothing refers to it
    throw;
  }
  if (!previous.empty() && previous != table.file) ::unlink((dir / previous).c_str());
}

}  // namespace panoptes::store
