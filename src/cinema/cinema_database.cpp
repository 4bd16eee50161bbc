#include "cinema/cinema_database.hpp"

#include <fcntl.h>
#include <sys/stat.h>

#include <algorithm>

#include "cinema/csv.hpp"
#include "core/error.hpp"
#include "store/bounded_json.hpp"
#include "store/manifest.hpp"
#include "store/safe_file.hpp"

namespace panoptes::cinema {
namespace fs = std::filesystem;

namespace {

// A value or name for messages: at most 80 bytes of it.
std::string shown(std::string_view s) {
  return s.size() <= 80 ? std::string(s) : std::string(s.substr(0, 80)) + "... (" + std::to_string(s.size()) + " bytes)";
}

void check_field(std::string_view v, const std::string& where, const std::string& what) {
  if (v.size() > kMaxField)
    throw FileError(where, what + " \"" + shown(v) + "\" is longer than " + std::to_string(kMaxField) + " bytes; refused");
}

// Spec A values are JSON numbers or strings; names in files use the text as ParaView writes it
// (integers without a decimal point).
std::string value_text(const nlohmann::json& v, const std::string& source, const std::string& name) {
  if (v.is_string()) {
    check_field(v.get_ref<const std::string&>(), source, "value of " + shown(name));
    return v.get<std::string>();
  }
  if (v.is_number_integer()) return v.dump();
  if (v.is_number()) return v.dump();
  throw FileError(source, "values of " + shown(name) + ": " + shown(v.dump()) + "; expected numbers or strings");
}

// Entries (files, links, directories) under dir, counted up to `enough`: a Spec A product larger than
// this cannot have an image per combination, so it is refused before it is expanded.
std::int64_t count_entries(const fs::path& dir, std::int64_t enough) {
  std::int64_t n = 0;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end && n < enough; it.increment(ec))
    ++n;
  return n;
}

}  // namespace

bool is_file_column(const std::string& name) {
  if (name.rfind("FILE", 0) != 0) return false;
  if (name.size() == 4) return true;
  if (name.size() > 5 && name[4] == '_') return true;
  return std::all_of(name.begin() + 4, name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

void parse_spec_d(std::string_view text, CinemaTable& t, const std::string& image_column) {
  CsvTable csv = parse_csv(text, t.source);
  std::vector<int> image_cols;
  for (std::size_t c = 0; c < csv.header.size(); ++c) {
    check_field(csv.header[c], t.source, "column name");
    if (is_file_column(csv.header[c])) image_cols.push_back(int(c));
  }
  std::vector<bool> skip(csv.header.size(), false);  // image columns: not parameters
  for (int c : image_cols) skip[std::size_t(c)] = true;
  if (!image_column.empty()) {
    const auto it = std::find(csv.header.begin(), csv.header.end(), image_column);
    if (it == csv.header.end())
      throw FileError(t.source, "--image-column \"" + shown(image_column) + "\" is not a column of the table");
    const int chosen = int(it - csv.header.begin());
    std::string others;
    for (int c : image_cols)
      if (c != chosen) others += (others.empty() ? "" : ", ") + csv.header[std::size_t(c)];
    if (!others.empty())
      t.warnings.push_back(t.source + ": images from column " + image_column + " (--image-column); column" +
                           (others.find(',') != std::string::npos ? "s " : " ") + others + " left out");
    skip[std::size_t(chosen)] = true;
    image_cols = {chosen};
  }
  if (image_cols.empty())
    throw FileError(t.source, "no FILE column (Cinema Spec D names each row's image in FILE; ParaView in FILE_png, FILE_jpg); "
                              "name the image column with --image-column");
  // ParaView writes one FILE_<ext> column per image format, one of them non-empty per row. A row with
  // two images (FILE and FILE2) holds two pictures of one view: the first image column is imported.
  if (image_cols.size() > 1) {
    std::size_t first_double = csv.rows.size();
    for (std::size_t r = 0; r < csv.rows.size() && first_double == csv.rows.size(); ++r) {
      int filled = 0;
      for (int c : image_cols) filled += !csv.rows[r][std::size_t(c)].empty();
      if (filled > 1) first_double = r;
    }
    if (first_double < csv.rows.size()) {
      std::string others;
      for (std::size_t i = 1; i < image_cols.size(); ++i) others += (i > 1 ? ", " : "") + csv.header[std::size_t(image_cols[i])];
      t.warnings.push_back(t.source + " line " + std::to_string(csv.lines[first_double]) + ": rows have " +
                           std::to_string(image_cols.size()) + " images (columns " + csv.header[std::size_t(image_cols[0])] +
                           ", " + others + "); imported " + csv.header[std::size_t(image_cols[0])] +
                           ", left out " + others + " (--image-column " + csv.header[std::size_t(image_cols[1])] +
                           " imports that one instead)");
      image_cols.resize(1);
    }
  }
  t.file_column = csv.header[std::size_t(image_cols[0])];
  for (std::size_t c = 0; c < csv.header.size(); ++c)
    if (!skip[c]) t.columns.push_back(csv.header[c]);
  if (std::int64_t(csv.rows.size()) > kMaxImages)
    throw FileError(t.source, std::to_string(csv.rows.size()) + " rows, more than the limit of " + std::to_string(kMaxImages) + " images");
  t.values.reserve(csv.rows.size());
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    std::vector<std::string>& in = csv.rows[r];
    const std::string line = t.source + " line " + std::to_string(csv.lines[r]);
    std::string file;
    for (int c : image_cols) {
      if (in[std::size_t(c)].empty()) continue;
      if (!file.empty())
        throw FileError(line, "two images in one row (" + t.file_column + " and " + csv.header[std::size_t(c)] +
                                  "); Panoptes imports one image per row");
      file = std::move(in[std::size_t(c)]);
      t.file_column = csv.header[std::size_t(c)];
    }
    check_field(file, line, "image path");
    std::vector<std::string> row;
    row.reserve(t.columns.size());
    for (std::size_t c = 0; c < in.size(); ++c) {
      if (skip[c]) continue;
      check_field(in[c], line, "value of column " + shown(csv.header[c]));
      row.push_back(std::move(in[c]));
    }
    t.values.push_back(std::move(row));
    t.files.push_back(std::move(file));
    t.where.push_back(line);
  }
  if (t.files.empty()) throw FileError(t.source, "no data rows; expected one row per image");
}

void parse_spec_a(std::string_view text, CinemaTable& t, std::int64_t max_rows) {
  store::JsonLimits limits;  // strings as the manifest's (metadata may hold a long pipeline description)
  limits.max_depth = 32;      // names, values and the pattern are checked against kMaxField below
  t.info = store::parse_bounded_json(text, t.source, limits, "Cinema info.json");
  const nlohmann::json& j = *t.info;
  if (!j.is_object() || !j.contains("name_pattern") || !j["name_pattern"].is_string())
    throw FileError(t.source, "no \"name_pattern\" string (Cinema Spec A, e.g. \"{time}/{phi}_{theta}.png\")");
  const char* list_key = j.contains("parameter_list") ? "parameter_list" : "arguments";
  if (!j.contains(list_key) || !j[list_key].is_object() || j[list_key].empty())
    throw FileError(t.source, "no \"parameter_list\" (or \"arguments\") object with the parameters and their values");
  const std::string pattern = j["name_pattern"].get<std::string>();
  check_field(pattern, t.source, "name_pattern");
  std::vector<std::vector<std::string>> axis_values;
  std::int64_t product = 1;
  for (const auto& [name, p] : j[list_key].items()) {
    check_field(name, t.source, "parameter name");
    if (!p.is_object() || !p.contains("values") || !p["values"].is_array() || p["values"].empty())
      throw FileError(t.source, std::string(list_key) + "." + shown(name) + ": expected an object with a non-empty \"values\" array");
    product *= std::int64_t(p["values"].size());  // each factor <= 2^23 (bounded JSON): no overflow before the check
    if (product > max_rows)
      throw FileError(t.source, "the parameters' values make more than " + std::to_string(max_rows) +
                                    " combinations, more than the database has files (each needs its own image); refused");
    t.columns.push_back(name);
    std::vector<std::string> v;
    for (const auto& x : p["values"]) v.push_back(value_text(x, t.source, name));
    axis_values.push_back(std::move(v));
  }
  // Every {name} of the pattern must be a parameter.
  for (std::size_t pos = pattern.find('{'); pos != std::string::npos; pos = pattern.find('{', pos + 1)) {
    const std::size_t end = pattern.find('}', pos);
    if (end == std::string::npos) throw FileError(t.source, "name_pattern \"" + shown(pattern) + "\" has an unclosed '{'");
    const std::string name = pattern.substr(pos + 1, end - pos - 1);
    if (std::find(t.columns.begin(), t.columns.end(), name) == t.columns.end())
      throw FileError(t.source, "name_pattern \"" + shown(pattern) + "\" uses {" + shown(name) + "}, which is not a parameter");
  }
  // The Cartesian product of every parameter's values, last parameter fastest.
  std::vector<std::size_t> idx(axis_values.size(), 0);
  t.values.reserve(std::size_t(product));
  for (;;) {
    std::vector<std::string> row;
    std::string file = pattern, where;
    for (std::size_t a = 0; a < axis_values.size(); ++a) {
      row.push_back(axis_values[a][idx[a]]);
      where += (a ? " " : "") + t.columns[a] + "=" + row.back();
      const std::string key = "{" + t.columns[a] + "}";
      for (std::size_t p = file.find(key); p != std::string::npos; p = file.find(key, p + row.back().size())) {
        file.replace(p, key.size(), row.back());
        if (file.size() > kMaxField) throw FileError(t.source, "name_pattern makes an image path longer than " + std::to_string(kMaxField) + " bytes");
      }
    }
    t.values.push_back(std::move(row));
    t.files.push_back(std::move(file));
    t.where.push_back(t.source + " (" + shown(where) + ")");
    std::size_t a = axis_values.size();
    while (a > 0) {
      --a;
      if (++idx[a] < axis_values[a].size()) break;
      idx[a] = 0;
      if (a == 0) return;
    }
    if (axis_values.empty()) return;
  }
}

CinemaTable read_cinema_database(const fs::path& dir, const std::string& image_column) {
  const store::FileHandle dfd = store::open_directory(dir);
  CinemaTable t;
  t.dir = dir;
  struct stat st{};
  t.has_info_js = ::fstatat(dfd.get(), "info.js", &st, AT_SYMLINK_NOFOLLOW) == 0;
  const bool has_csv = bool(store::open_regular_file(dfd.get(), "data.csv", kMaxTableBytes, "Cinema table", dir, true));
  const bool has_info = bool(store::open_regular_file(dfd.get(), "info.json", kMaxInfoBytes, "Cinema info.json", dir, true));
  if (bool(store::open_regular_file(dfd.get(), "panoptes-cinema.json", store::kMaxManifestBytes, "Panoptes camera file", dir, true))) {
    const std::string text = store::read_regular_file(dfd.get(), "panoptes-cinema.json", store::kMaxManifestBytes, "Panoptes camera file", dir);
    t.panoptes = store::parse_bounded_json(text, (dir / "panoptes-cinema.json").string(), {}, "Panoptes camera file");
  }
  if (has_csv) {
    t.spec = "D";
    t.source = (dir / "data.csv").string();
    parse_spec_d(store::read_regular_file(dfd.get(), "data.csv", kMaxTableBytes, "Cinema table", dir), t, image_column);
    if (has_info) {  // Ascent writes both; its info.json tells the producer
      CinemaTable a;
      a.source = (dir / "info.json").string();
      store::JsonLimits limits;
      limits.max_depth = 32;
      a.info = store::parse_bounded_json(store::read_regular_file(dfd.get(), "info.json", kMaxInfoBytes, "Cinema info.json", dir),
                                         a.source, limits, "Cinema info.json");
      t.info = std::move(a.info);
    }
    return t;
  }
  if (has_info) {
    if (!image_column.empty())
      throw FileError((dir / "info.json").string(), "--image-column applies to a data.csv table (Spec D); Spec A names its images by name_pattern");
    t.spec = "A";
    t.source = (dir / "info.json").string();
    const std::string text = store::read_regular_file(dfd.get(), "info.json", kMaxInfoBytes, "Cinema info.json", dir);
    parse_spec_a(text, t, std::min<std::int64_t>(kMaxImages, std::max<std::int64_t>(1, count_entries(dir, kMaxImages))));
    return t;
  }
  throw FileError(dir.string(), "neither data.csv (Cinema Spec D) nor info.json (Spec A) found; not a Cinema database");
}

fs::path resolve_inside(const fs::path& dir, const std::string& file, const std::string& where) {
  const fs::path rel(file);
  if (file.empty()) throw FileError(where, "empty FILE entry; expected the path of an image");
  if (rel.is_absolute())
    throw FileError(where, "FILE \"" + shown(file) + "\" is an absolute path; Cinema paths are relative to the database");
  const fs::path base = fs::weakly_canonical(dir);
  const fs::path resolved = fs::weakly_canonical(base / rel);
  const auto [b, r] = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
  if (b != base.end())
    throw FileError(where, "FILE \"" + shown(file) + "\" resolves to " + resolved.string() + ", outside the database " +
                               base.string() + "; refused");
  return resolved;
}

}  // namespace panoptes::cinema
