#pragma once
// The manifest's JSON, one write/read pair per section (manifest_sections.cpp), in the order the
// manifest holds them. Adding a section to the manifest is one pair here, called from manifest_json
// and manifest_from_json (manifest.cpp). Private to the store.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "store/camera_table.hpp"
#include "store/manifest.hpp"

namespace panoptes::store::manifest_sections {

using json = nlohmann::json;

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

// schema_version, format, title, status, frames_written, movie_pattern
void write_header(json& j, const Manifest& m);
void read_header(const Reader& r, const json& j, Manifest& m);
// provenance
void write_provenance(json& j, const Manifest& m);
void read_provenance(const Reader& r, const json& j, Manifest& m);
// domain
void write_domain(json& j, const Manifest& m);
void read_domain(const Reader& r, const json& j, Manifest& m);
// playback_fps
void write_playback(json& j, const Manifest& m);
void read_playback(const Reader& r, const json& j, Manifest& m);
// frame_checks
void write_frame_checks(json& j, const Manifest& m);
void read_frame_checks(const Reader& r, const json& j, Manifest& m);
void write_layout(json& j, const Manifest& m);
void read_layout(const Reader& r, const json& j, Manifest& m);
// times, time_units
void write_times(json& j, const Manifest& m);
void read_times(const Reader& r, const json& j, Manifest& m);
// fields
void write_fields(json& j, const Manifest& m);
void read_fields(const Reader& r, const json& j, Manifest& m);
// image
void write_image(json& j, const Manifest& m);
void read_image(const Reader& r, const json& j, Manifest& m);
// video
void write_video(json& j, const Manifest& m);
void read_video(const Reader& r, const json& j, Manifest& m);
// rig
void write_rig(json& j, const Manifest& m);
void read_rig(const Reader& r, const json& j, Manifest& m);
// camera_table or cameras, navigation
void write_cameras(json& j, const Manifest& m, const CameraTableRef* table);
/// Returns the camera table the manifest refers to (its file is read by the caller, after the tasks).
std::optional<CameraTableRef> read_cameras(const Reader& r, const json& j, Manifest& m, const std::filesystem::path& dir);
// axes
void write_axes(json& j, const Manifest& m);
void read_axes(const Reader& r, const json& j, Manifest& m);
// tasks
void write_tasks(json& j, const Manifest& m);
void read_tasks(const Reader& r, const json& j, Manifest& m);

}  // namespace panoptes::store::manifest_sections
