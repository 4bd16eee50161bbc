#pragma once
// Reading Cinema image databases (https://cinemascience.github.io): Spec D (data.csv: one row per
// image, one column per parameter, the image path in the column FILE) and the older Spec A
// (info.json: parameter_list with each parameter's values, and name_pattern, e.g.
// "{time}/{phi}_{theta}.png", as ParaView and Ascent write). Both become one table of rows.
#include <filesystem>
#include <string>
#include <vector>

namespace panoptes::cinema {

/// A Cinema database as a table: parameter columns (FILE excluded) and one row per image.
struct CinemaTable {
  std::filesystem::path dir;               ///< the .cdb directory
  std::string spec;                        ///< "D" or "A"
  std::string source;                      ///< data.csv or info.json path, for messages
  std::vector<std::string> columns;        ///< parameter names, in file order
  std::vector<std::vector<std::string>> values;  ///< values[row][column], as text ("" = not set)
  std::vector<std::string> files;          ///< image path of each row, relative to dir
  std::vector<std::string> where;          ///< per row, where it came from ("line 7", "time=2 phi=30 ...")
};

/// Reads IN.cdb: data.csv if present (Spec D), else info.json (Spec A). Throws FileError naming the
/// file when neither exists or either is malformed (see parse_csv; Spec A: not JSON, no name_pattern,
/// a {placeholder} without a parameter, a parameter without values).
CinemaTable read_cinema_database(const std::filesystem::path& dir);

/// Checks that `file` (a FILE entry) names a path inside `dir`: relative, no ".." escaping, and,
/// resolved through symbolic links, still inside. Returns the resolved path. Throws FileError naming
/// the entry and `where` otherwise.
std::filesystem::path resolve_inside(const std::filesystem::path& dir, const std::string& file, const std::string& where);

}  // namespace panoptes::cinema
