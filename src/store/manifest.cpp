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
#include "store/manifest_sections.hpp"

namespace panoptes::store {

using nlohmann::json;

std::string_view to_string(Layout layout) { return layout == Layout::packed ? "packed" : "files"; }

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

// The manifest as JSON: with `table`, the cameras and the graph are replaced by a reference to it.
json manifest_json(const Manifest& m, const CameraTableRef* table) {
  using namespace manifest_sections;
  json j;
  write_header(j, m);
  write_provenance(j, m);
  write_domain(j, m);
  write_playback(j, m);
  write_frame_checks(j, m);
  write_layout(j, m);
  write_times(j, m);
  write_fields(j, m);
  write_image(j, m);
  write_video(j, m);
  write_rig(j, m);
  write_cameras(j, m, table);
  write_axes(j, m);
  write_tasks(j, m);
  return j;
}

}  // namespace

json to_json(const Manifest& m) { return manifest_json(m, nullptr); }

Manifest manifest_from_json(const json& j, const std::string& source, const std::filesystem::path& dir) {
  using namespace manifest_sections;
  const Reader r{source};
  if (!j.is_object()) r.fail("manifest", "expected a JSON object at the top level");
  Manifest m;
  read_header(r, j, m);
  read_provenance(r, j, m);
  read_domain(r, j, m);
  read_playback(r, j, m);
  read_frame_checks(r, j, m);
  read_layout(r, j, m);
  read_times(r, j, m);
  read_fields(r, j, m);
  read_image(r, j, m);
  read_video(r, j, m);
  read_rig(r, j, m);
  const std::optional<CameraTableRef> table = read_cameras(r, j, m, dir);
  read_axes(r, j, m);
  read_tasks(r, j, m);
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
