#include "cinema/csv.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <set>

#include "core/error.hpp"

namespace panoptes::cinema {

int CsvTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return int(i);
  return -1;
}

CsvTable parse_csv(std::string_view text, const std::string& source) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  CsvTable table;
  std::vector<std::string> row;
  std::string field;
  int line = 1, row_line = 1;
  bool quoted = false, was_quoted = false, any = false;
  auto end_field = [&] {
    row.push_back(std::move(field));
    field.clear();
    was_quoted = false;
  };
  auto end_row = [&] {
    end_field();
    const bool blank = row.size() == 1 && row[0].empty() && !any;
    if (!blank) {
      if (table.header.empty()) {
        table.header = std::move(row);
      } else {
        if (row.size() != table.header.size())
          throw FileError(source, "line " + std::to_string(row_line) + " has " + std::to_string(row.size()) +
                                      " fields; the header has " + std::to_string(table.header.size()));
        table.rows.push_back(std::move(row));
        table.lines.push_back(row_line);
      }
    }
    row.clear();
    any = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          field += '"';
          ++i;
        } else {
          quoted = false;
        }
      } else {
        if (c == '\n') ++line;
        field += c;
      }
      continue;
    }
    if (c == '"') {
      if (!field.empty() || was_quoted)
        throw FileError(source, "line " + std::to_string(line) + ": a quote inside an unquoted field (RFC 4180 quotes whole fields)");
      quoted = was_quoted = any = true;
    } else if (c == ',') {
      any = true;
      end_field();
    } else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      continue;  // CRLF: the LF ends the row
    } else if (c == '\n') {
      end_row();
      ++line;
      row_line = line;
    } else {
      if (was_quoted)
        throw FileError(source, "line " + std::to_string(line) + ": text after a closing quote");
      field += c;
      any = true;
    }
  }
  if (quoted) throw FileError(source, "line " + std::to_string(row_line) + ": unterminated quoted field");
  if (!field.empty() || !row.empty() || any) end_row();
  if (table.header.empty()) throw FileError(source, "empty CSV file; expected a header row");
  std::set<std::string> names;
  for (std::size_t i = 0; i < table.header.size(); ++i) {
    if (table.header[i].empty()) throw FileError(source, "column " + std::to_string(i + 1) + " has an empty name");
    if (!names.insert(table.header[i]).second)
      throw FileError(source, "column name \"" + table.header[i] + "\" appears twice");
  }
  return table;
}

std::string csv_field(std::string_view v) {
  const bool quote = v.find_first_of(",\"\r\n") != std::string_view::npos ||
                     (!v.empty() && (v.front() == ' ' || v.back() == ' '));
  if (!quote) return std::string(v);
  std::string s = "\"";
  for (char c : v) {
    if (c == '"') s += '"';
    s += c;
  }
  return s + '"';
}

std::string format_float(double value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  std::string s(buf, r.ptr);
  if (std::isfinite(value) && s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string format_value(double v) {
  if (!std::isfinite(v)) return format_float(v);
  if (std::abs(v) < 1e-9) return "0";
  char buf[64];
  const float f = float(v);
  if (std::isfinite(f) && double(f) == v) {
    const auto r = std::to_chars(buf, buf + sizeof buf, f);
    return std::string(buf, r.ptr);
  }
  std::snprintf(buf, sizeof buf, "%.12g", v);
  const double snapped = std::strtod(buf, nullptr);
  if (std::abs(snapped - v) <= 1e-13 * std::max(1.0, std::abs(v))) v = snapped;
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

bool parse_number(std::string_view t, double& value) {
  while (!t.empty() && t.front() == ' ') t.remove_prefix(1);
  while (!t.empty() && t.back() == ' ') t.remove_suffix(1);
  if (t.starts_with('+')) t.remove_prefix(1);
  if (t.empty()) return false;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), value);
  return r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(value);
}

}  // namespace panoptes::cinema
