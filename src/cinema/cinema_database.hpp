#pragma once
// Reading Cinema image databases (https://cinemascience.github.io): Spec D (data.csv: one row per
// image, one column per parameter, the image path in the column FILE, or FILE_<ext> as ParaView 5.11
// names it) and the older Spec A (info.json: the parameters and their values under "parameter_list"
// or, as cinema_python and Ascent write it, "arguments", and name_pattern, e.g.
// "{time}/{phi}_{theta}.png"). Both become one table of rows.
//
// A Cinema database may come from anyone: its files are read through the store's safe readers (no
// symbolic link followed, FIFOs and devices refused, sizes bounded), info.json through the bounded
// JSON parser (nesting, string and container sizes), every field is bounded, and a Spec A
// parameter product is never expanded beyond the number of files the database holds.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace panoptes::cinema {

/// Largest data.csv read (bytes).
inline constexpr std::uint64_t kMaxTableBytes = std::uint64_t(64) << 20;
/// Largest info.json (and Panoptes' own panoptes-cinema.json) read (bytes).
inline constexpr std::uint64_t kMaxInfoBytes = std::uint64_t(16) << 20;
/// Longest column name or value (bytes): names and values become task names and parameters, which
/// the manifest keeps; far above any real one, far below the manifest's 1 MiB string bound.
inline constexpr std::size_t kMaxField = 4096;
/// Most images (rows) one Cinema database may describe.
inline constexpr std::int64_t kMaxImages = std::int64_t(1) << 22;

/// A Cinema database as a table: parameter columns (image column excluded) and one row per image.
struct CinemaTable {
  std::filesystem::path dir;               ///< the .cdb directory
  std::string spec;                        ///< "D" or "A"
  std::string source;                      ///< data.csv or info.json path, for messages
  std::vector<std::string> columns;        ///< parameter names, in file order
  std::vector<std::vector<std::string>> values;  ///< values[row][column], as text ("" = not set)
  std::vector<std::string> files;          ///< image path of each row, relative to dir
  std::vector<std::string> where;          ///< per row, where it came from ("line 7", "time=2 phi=30 ...")
  std::string file_column = "FILE";        ///< Spec D: the image column's name ("FILE", "FILE_png")
  std::optional<nlohmann::json> info;      ///< info.json when the database has one (Spec A or beside data.csv)
  bool has_info_js = false;                ///< info.js exists (Ascent copies its viewer's data there)
  std::optional<nlohmann::json> panoptes;  ///< panoptes-cinema.json: written by Panoptes' export
  /// What was read differently from the file's face value, one line each naming the file, the column
  /// and the option that changes it (e.g. a second image column left out); the import reports them.
  std::vector<std::string> warnings;
};

/// An image column's name: FILE, FILE_<ext> (ParaView 5.11: one per image format, one non-empty per
/// row) or FILE<digits> (a second image per row, e.g. FILE2).
bool is_file_column(const std::string& name);

/// Reads IN.cdb: data.csv if present (Spec D), else info.json (Spec A). Throws FileError naming the
/// file when neither exists, either is not a regular file (link, FIFO, device) or too large, or
/// either is malformed (see parse_csv; Spec A: not JSON, no name_pattern, a {placeholder} without a
/// parameter, a parameter without values, more combinations than the database has files).
/// `image_column` (--image-column): the column that holds each row's image (empty = FILE, or the one
/// non-empty FILE_<ext> of each row; when a row has two images, the first image column, with a warning
/// naming the others).
CinemaTable read_cinema_database(const std::filesystem::path& dir, const std::string& image_column = {});

/// Parses data.csv text (Spec D) into `t` (columns, values, files, where, file_column, warnings);
/// `image_column` as read_cinema_database's. Throws FileError naming `t.source` (an --image-column that
/// is not a column of the table). Exposed for the fuzz target.
void parse_spec_d(std::string_view text, CinemaTable& t, const std::string& image_column = {});

/// Parses info.json text (Spec A) into `t`: t.info, columns and every combination of the parameter
/// values as rows, refusing more than `max_rows` combinations. Throws FileError naming `t.source`.
/// Exposed for the fuzz target.
void parse_spec_a(std::string_view text, CinemaTable& t, std::int64_t max_rows);

/// Checks that `file` (a FILE entry) names a path inside `dir`: relative, no ".." escaping, and,
/// resolved through symbolic links, still inside. Returns the resolved path. Throws FileError naming
/// the entry and `where` otherwise.
std::filesystem::path resolve_inside(const std::filesystem::path& dir, const std::string& file, const std::string& where);

}  // namespace panoptes::cinema
