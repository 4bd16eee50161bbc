#pragma once
// What the web player reads about a database, as JSON built from the store API (never from the raw
// files, so schema 1 and 2 databases look the same to the browser).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "store/database.hpp"
#include "web/mp4_fragments.hpp"

namespace panoptes::web {

/// What database_json puts in and how much of it.
struct DatabaseJsonOptions {
  /// The inline camera form even for a database with a camera table (see database_json).
  bool inline_cameras = false;
  /// `times` holds the frame times the manifest lists, from frame `times_from`, at most `max_times`
  /// of them (serve pages them; a frame past the listed ones has time = its index, as
  /// store::Manifest::frame_time says, so nothing is built for times the manifest does not hold).
  std::size_t times_from = 0;
  std::size_t max_times = std::size_t(-1);
  /// Frames the movie files can hold, as checked by the caller (serve: the first stream's fragment
  /// index when the manifest claims more frames than its bytes could hold); -1 = not checked. A smaller
  /// value than the manifest's claim becomes `frames`, with the claim in `frames_claimed` and `warning`.
  std::int64_t frames_backed = -1;
};

/// Everything the player needs to open a database: title, status, frame count, fps, image size,
/// times, tasks and parameter axes, the movie file-name pattern, and the cameras: for a database with
/// a binary camera table (schema 2) `cameras` is {count, table: file name in the database, bytes} and
/// the player reads that file itself; for inline cameras (schema 1) it holds the columns latitude,
/// longitude, shell, position, look-at and up, and `graph` the navigation rows [left, right, up, down,
/// in, out] (-1 = none; empty without a graph). `inline_cameras` forces the inline form (small
/// databases, tools, and the test that checks the player's table parser against it). Its size is
/// bounded by the manifest's and the camera table's, never by a count they claim (issue 31: a 1.3 kB
/// manifest claiming 2^31-1 frames made a `times` array of 2^31 numbers): `times` has the listed times
/// only, with `times_from` (first frame listed) and `times_listed` (how many the manifest lists for
/// the frames there are).
nlohmann::json database_json(const store::Database& db, const DatabaseJsonOptions& options);
inline nlohmann::json database_json(const store::Database& db, bool inline_cameras = false) {
  DatabaseJsonOptions o;
  o.inline_cameras = inline_cameras;
  return database_json(db, o);
}

/// The fragment index of one movie as JSON: {"file_size", "init_size", "fragments": [[offset, size,
/// first_frame, frames], ...]}.
nlohmann::json fragment_index_json(const FragmentIndex& index);

/// The URL path of a file of the database relative to the player's base ("db/" + its path inside
/// `db_dir`), as `panoptes serve` and export-web's db/ directory serve it. Throws Error when `file`
/// is not inside `db_dir`.
std::string database_file_url(const std::filesystem::path& db_dir, const std::filesystem::path& file);

/// The index of one stream of a packed database as JSON (docs/web.md, "Packed databases"): the files
/// that hold its bytes, where its init segment is and its fragments, each naming its file:
/// {"files": ["db/packs/s0-r0.pack", ...], "init": [file, offset, size], "init_size": size,
///  "fragments": [[offset, size, first_frame, frames, file], ...]}. The files layout's index
/// (fragment_index_json) is the same without "files" and "init" (file 0 = the movie, init at 0).
nlohmann::json packed_index_json(const store::PackedStream& stream, const std::filesystem::path& db_dir);

}  // namespace panoptes::web
