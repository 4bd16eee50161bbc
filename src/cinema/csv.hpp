#pragma once
// CSV as Cinema Spec D uses it (RFC 4180): comma-separated, fields with commas, quotes or line breaks
// quoted with '"' ('"' doubled inside), CRLF or LF line ends, UTF-8 (a leading BOM is skipped).
#include <string>
#include <string_view>
#include <vector>

namespace panoptes::cinema {

/// A parsed CSV file: the header row and the data rows (each as long as the header).
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  /// 1-based line number in the file where each row starts (for error messages).
  std::vector<int> lines;
  /// Index of the column called `name` (exact match), or -1.
  int column(std::string_view name) const;
};

/// Parses CSV text. `source` names the file in error messages. Throws panoptes::Error on an
/// unterminated quote, a quote inside an unquoted field, a row whose field count differs from the
/// header's, an empty or duplicate column name. Empty lines are skipped.
CsvTable parse_csv(std::string_view text, const std::string& source);

/// One field, quoted only when it must be (comma, quote, CR or LF inside, or leading/trailing space).
std::string csv_field(std::string_view value);

/// A floating-point value that always reads back as a float: the shortest representation that
/// round-trips, with ".0" appended when it would look like an integer ("2" -> "2.0"; "1e+20" stays).
std::string format_float(double value);

/// A number as Cinema viewers should show it: the shortest decimal that reads back to the same value,
/// after removing the noise of single-precision storage and of trigonometry: a value that is a float
/// prints as that float's shortest decimal ("0.3", not "0.30000001192092896"), one within 1e-13 (relative) of a
/// 12-significant-digit decimal prints as that decimal, |v| < 1e-9 prints as "0". Integers print
/// without a decimal point ("2").
std::string format_value(double value);

/// Parses a whole field as a finite double (surrounding spaces allowed); false if it is not one.
bool parse_number(std::string_view text, double& value);

}  // namespace panoptes::cinema
