#include "cinema/cinema_database.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cinema/csv.hpp"
#include "core/error.hpp"

namespace panoptes::cinema {
namespace fs = std::filesystem;

namespace {

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path.string(), "cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Spec A values are JSON numbers or strings; names in files use the text as ParaView writes it
// (integers without a decimal point).
std::string value_text(const nlohmann::ordered_json& v, const std::string& source, const std::string& name) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) {
    std::string s = v.dump();
    return s;
  }
  throw FileError(source, "parameter_list." + name + ".values: " + v.dump() + "; expected numbers or strings");
}

CinemaTable read_spec_d(const fs::path& dir) {
  CinemaTable t;
  t.dir = dir;
  t.spec = "D";
  t.source = (dir / "data.csv").string();
  const CsvTable csv = parse_csv(read_text(dir / "data.csv"), t.source);
  const int file = csv.column("FILE");
  if (file < 0) throw FileError(t.source, "no FILE column (Cinema Spec D names each row's image in FILE)");
  for (std::size_t c = 0; c < csv.header.size(); ++c)
    if (int(c) != file) t.columns.push_back(csv.header[c]);
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    std::vector<std::string> row;
    for (std::size_t c = 0; c < csv.header.size(); ++c)
      if (int(c) != file) row.push_back(csv.rows[r][c]);
    t.values.push_back(std::move(row));
    t.files.push_back(csv.rows[r][std::size_t(file)]);
    t.where.push_back(t.source + " line " + std::to_string(csv.lines[r]));
  }
  if (t.files.empty()) throw FileError(t.source, "no data rows; expected one row per image");
  return t;
}

CinemaTable read_spec_a(const fs::path& dir) {
  CinemaTable t;
  t.dir = dir;
  t.spec = "A";
  t.source = (dir / "info.json").string();
  nlohmann::ordered_json j;  // parameters keep the file's order
  try {
    j = nlohmann::ordered_json::parse(read_text(dir / "info.json"));
  } catch (const nlohmann::json::exception& e) {
    throw FileError(t.source, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object() || !j.contains("name_pattern") || !j["name_pattern"].is_string())
    throw FileError(t.source, "no \"name_pattern\" string (Cinema Spec A, e.g. \"{time}/{phi}_{theta}.png\")");
  if (!j.contains("parameter_list") || !j["parameter_list"].is_object() || j["parameter_list"].empty())
    throw FileError(t.source, "no \"parameter_list\" object with the parameters and their values");
  const std::string pattern = j["name_pattern"].get<std::string>();
  std::vector<std::vector<std::string>> axis_values;
  for (const auto& [name, p] : j["parameter_list"].items()) {
    if (!p.is_object() || !p.contains("values") || !p["values"].is_array() || p["values"].empty())
      throw FileError(t.source, "parameter_list." + name + ": expected an object with a non-empty \"values\" array");
    t.columns.push_back(name);
    std::vector<std::string> v;
    for (const auto& x : p["values"]) v.push_back(value_text(x, t.source, name));
    axis_values.push_back(std::move(v));
  }
  // Every {name} of the pattern must be a parameter.
  for (std::size_t pos = pattern.find('{'); pos != std::string::npos; pos = pattern.find('{', pos + 1)) {
    const std::size_t end = pattern.find('}', pos);
    if (end == std::string::npos) throw FileError(t.source, "name_pattern \"" + pattern + "\" has an unclosed '{'");
    const std::string name = pattern.substr(pos + 1, end - pos - 1);
    bool known = false;
    for (const auto& c : t.columns) known = known || c == name;
    if (!known)
      throw FileError(t.source, "name_pattern \"" + pattern + "\" uses {" + name + "}, which is not in parameter_list");
  }
  // The Cartesian product of every parameter's values, last parameter fastest.
  std::vector<std::size_t> idx(axis_values.size(), 0);
  for (;;) {
    std::vector<std::string> row;
    std::string file = pattern, where;
    for (std::size_t a = 0; a < axis_values.size(); ++a) {
      row.push_back(axis_values[a][idx[a]]);
      where += (a ? " " : "") + t.columns[a] + "=" + row.back();
      const std::string key = "{" + t.columns[a] + "}";
      for (std::size_t p = file.find(key); p != std::string::npos; p = file.find(key, p + row.back().size()))
        file.replace(p, key.size(), row.back());
    }
    t.values.push_back(std::move(row));
    t.files.push_back(file);
    t.where.push_back(t.source + " (" + where + ")");
    std::size_t a = axis_values.size();
    while (a > 0) {
      --a;
      if (++idx[a] < axis_values[a].size()) break;
      idx[a] = 0;
      if (a == 0) return t;
    }
    if (axis_values.empty()) return t;
  }
}

}  // namespace

CinemaTable read_cinema_database(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw FileError(dir.string(), "not a directory; expected a Cinema database (.cdb)");
  if (fs::exists(dir / "data.csv")) return read_spec_d(dir);
  if (fs::exists(dir / "info.json")) return read_spec_a(dir);
  throw FileError(dir.string(), "neither data.csv (Cinema Spec D) nor info.json (Spec A) found; not a Cinema database");
}

fs::path resolve_inside(const fs::path& dir, const std::string& file, const std::string& where) {
  const fs::path rel(file);
  if (file.empty()) throw FileError(where, "empty FILE entry; expected the path of an image");
  if (rel.is_absolute())
    throw FileError(where, "FILE \"" + file + "\" is an absolute path; Cinema paths are relative to the database");
  const fs::path base = fs::weakly_canonical(dir);
  const fs::path resolved = fs::weakly_canonical(base / rel);
  const auto [b, r] = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
  if (b != base.end())
    throw FileError(where, "FILE \"" + file + "\" resolves to " + resolved.string() + ", outside the database " +
                               base.string() + "; refused");
  return resolved;
}

}  // namespace panoptes::cinema
