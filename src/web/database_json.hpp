#pragma once
// What the web player reads about a database, as JSON built from the store API (never from the raw
// files, so schema 1 and 2 databases look the same to the browser).
#include <nlohmann/json.hpp>

#include "store/database.hpp"
#include "web/mp4_fragments.hpp"

namespace panoptes::web {

/// Everything the player needs to open a database: title, status, frame count, fps, image size,
/// times, tasks and parameter axes, the movie file-name pattern, and the cameras: for a database with
/// a binary camera table (schema 2) `cameras` is {count, table: file name in the database, bytes} and
/// the player reads that file itself; for inline cameras (schema 1) it holds the columns latitude,
/// longitude, shell, position, look-at and up, and `graph` the navigation rows [left, right, up, down,
/// in, out] (-1 = none; empty without a graph). `inline_cameras` forces the inline form (small
/// databases, tools, and the test that checks the player's table parser against it).
nlohmann::json database_json(const store::Database& db, bool inline_cameras = false);

/// The fragment index of one movie as JSON: {"file_size", "init_size", "fragments": [[offset, size,
/// first_frame, frames], ...]}.
nlohmann::json fragment_index_json(const FragmentIndex& index);

}  // namespace panoptes::web
