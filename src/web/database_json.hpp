#pragma once
// What the web player reads about a database, as JSON built from the store API (never from the raw
// files, so schema 1 and 2 databases look the same to the browser).
#include <nlohmann/json.hpp>

#include "store/database.hpp"
#include "web/mp4_fragments.hpp"

namespace panoptes::web {

/// Everything the player needs to open a database: title, status, frame count, fps, image size,
/// times, tasks and parameter axes, the movie file-name pattern, and per camera (column-wise, so
/// 10^5 cameras stay a few MB) latitude, longitude, shell, position, look-at and up, plus the
/// navigation graph as rows [left, right, up, down, in, out] (-1 = none; empty without a graph).
nlohmann::json database_json(const store::Database& db);

/// The fragment index of one movie as JSON: {"file_size", "init_size", "fragments": [[offset, size,
/// first_frame, frames], ...]}.
nlohmann::json fragment_index_json(const FragmentIndex& index);

}  // namespace panoptes::web
