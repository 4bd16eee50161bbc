#include "core/field_sidecar.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/file_read.hpp"

namespace panoptes {

namespace {

using json = nlohmann::json;

/// Largest sidecar read: a real one is ~400 bytes.
constexpr std::uint64_t kMaxSidecarBytes = 1 << 20;

std::string shown(const json& v) {
  std::string s = v.dump();
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

// Checks one key of the object and hands its value to `take`; absent keys are an error when required.
class Reader {
 public:
  Reader(const json& j, const std::string& path) : j_(j), path_(path) {}

  [[noreturn]] void fail(const std::string& key, const std::string& expected, const json* got) const {
    throw FileError(path_, key + ": expected " + expected + (got ? ", got " + shown(*got) : ", but the key is missing"));
  }
  const json* find(const std::string& key, bool required, const std::string& expected) const {
    const auto it = j_.find(key);
    if (it == j_.end() || it->is_null()) {
      if (required) fail(key, expected, nullptr);
      return nullptr;
    }
    return &*it;
  }
  void text(const std::string& key, std::string& out, bool required = false) const {
    const std::string expected = "a string";
    if (const json* v = find(key, required, expected)) {
      if (!v->is_string()) fail(key, expected, v);
      out = v->get<std::string>();
    }
  }
  std::optional<double> number(const std::string& key) const {
    const std::string expected = "a finite number";
    const json* v = find(key, false, expected);
    if (!v) return std::nullopt;
    if (!v->is_number() || !std::isfinite(v->get<double>())) fail(key, expected, v);
    return v->get<double>();
  }
  // Three finite numbers, each > 0 when `positive`.
  bool vec3(const std::string& key, Vec3& out, bool required, bool positive) const {
    const std::string expected = positive ? "an array of 3 numbers > 0" : "an array of 3 finite numbers";
    const json* v = find(key, required, expected);
    if (!v) return false;
    if (!v->is_array() || v->size() != 3) fail(key, expected, v);
    for (int a = 0; a < 3; ++a) {
      const json& x = (*v)[std::size_t(a)];
      if (!x.is_number() || !std::isfinite(x.get<double>()) || (positive && !(x.get<double>() > 0))) fail(key, expected, v);
      out[a] = x.get<double>();
    }
    return true;
  }

 private:
  const json& j_;
  std::string path_;
};

}  // namespace

std::string field_sidecar_path(const std::string& data_path) {
  return std::filesystem::path(data_path).replace_extension(".json").string();
}

std::string field_sidecar_json(const FieldSidecar& s) {
  std::vector<std::pair<const char*, json>> rows;
  rows.emplace_back("format", kFieldSidecarFormat);
  rows.emplace_back("version", kFieldSidecarVersion);
  if (!s.data.empty()) rows.emplace_back("data", s.data);
  if (!s.field.empty()) rows.emplace_back("field", s.field);
  if (!s.field_units.empty()) rows.emplace_back("field_units", s.field_units);
  rows.emplace_back("dims", json::array({s.dims[0], s.dims[1], s.dims[2]}));
  if (s.origin) rows.emplace_back("origin", json::array({s.origin->x, s.origin->y, s.origin->z}));
  rows.emplace_back("spacing", json::array({s.spacing.x, s.spacing.y, s.spacing.z}));
  if (!s.length_units.empty()) rows.emplace_back("length_units", s.length_units);
  rows.emplace_back("up_axis", s.up_axis);
  if (s.time) rows.emplace_back("time", *s.time);
  if (!s.time_units.empty()) rows.emplace_back("time_units", s.time_units);
  if (s.step) rows.emplace_back("step", *s.step);
  std::string out = "{\n";
  for (std::size_t i = 0; i < rows.size(); ++i)
    out += "  \"" + std::string(rows[i].first) + "\": " + rows[i].second.dump() + (i + 1 < rows.size() ? ",\n" : "\n");
  return out + "}\n";
}

FieldSidecar parse_field_sidecar(const std::string& text, const std::string& path) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw FileError(path, std::string("malformed JSON: ") + e.what());
  }
  if (!j.is_object()) throw FileError(path, "expected a JSON object (a field sidecar), got " + shown(j));
  const Reader r(j, path);
  std::string format;
  r.text("format", format);
  if (!format.empty() && format != kFieldSidecarFormat)
    r.fail("format", "\"" + std::string(kFieldSidecarFormat) + "\"", &j["format"]);
  const std::string version_expected = "the integer " + std::to_string(kFieldSidecarVersion) +
                                       " (this build reads version " + std::to_string(kFieldSidecarVersion) + ")";
  const json* version = r.find("version", true, version_expected);
  if (!version->is_number_integer() || version->get<long long>() != kFieldSidecarVersion)
    r.fail("version", version_expected, version);

  FieldSidecar s;
  r.text("data", s.data);
  if (s.data.find('/') != std::string::npos) r.fail("data", "a file name without a directory", &j["data"]);
  r.text("field", s.field);
  r.text("field_units", s.field_units);
  {
    const std::string expected = "an array of 3 integers >= 1 (points along x, y, z)";
    const json* d = r.find("dims", true, expected);
    if (!d->is_array() || d->size() != 3) r.fail("dims", expected, d);
    for (int a = 0; a < 3; ++a) {
      const json& x = (*d)[std::size_t(a)];
      if (!x.is_number_integer() || x.get<long long>() < 1 || x.get<long long>() > (1 << 24)) r.fail("dims", expected, d);
      s.dims[std::size_t(a)] = int(x.get<long long>());
    }
  }
  Vec3 origin;
  if (r.vec3("origin", origin, false, false)) s.origin = origin;
  r.vec3("spacing", s.spacing, true, true);
  r.text("length_units", s.length_units);
  r.text("up_axis", s.up_axis, true);
  if (s.up_axis != "z_up" && s.up_axis != "z_down")
    r.fail("up_axis", "\"z_up\" or \"z_down\" (z is depth)", &j["up_axis"]);
  s.time = r.number("time");
  r.text("time_units", s.time_units);
  if (const json* step = r.find("step", false, "an integer >= 0")) {
    if (!step->is_number_integer() || step->get<long long>() < 0) r.fail("step", "an integer >= 0", step);
    s.step = step->get<long long>();
  }
  return s;
}

FieldSidecar read_field_sidecar(const std::string& path) {
  return parse_field_sidecar(read_regular_file(path, kMaxSidecarBytes, "field sidecar"), path);
}

void write_field_sidecar(const std::string& path, const FieldSidecar& sidecar) {
  const std::string text = field_sidecar_json(sidecar);
  const std::string tmp = path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(std::random_device{}());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!(out << text) || !out.flush()) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw FileError(path, "cannot write the field sidecar");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw FileError(path, "cannot write the field sidecar: " + ec.message());
  }
}

std::optional<FieldSidecar> find_field_sidecar(const std::string& data_path) {
  const std::string path = field_sidecar_path(data_path);
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(path, ec))) return std::nullopt;
  FieldSidecar s = read_field_sidecar(path);
  const std::string name = std::filesystem::path(data_path).filename().string();
  if (!s.data.empty() && s.data != name)
    throw FileError(path, "data: the sidecar describes \"" + s.data + "\", but it sits beside \"" + name +
                              "\" (copied or renamed without its array?); expected \"" + name + "\"");
  return s;
}

}  // namespace panoptes
