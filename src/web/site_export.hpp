#pragma once
// `panoptes export-web`: the web player as a static site that any static web server can host.
#include <cstdint>
#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

namespace panoptes::web {

/// The list of files an export wrote, one relative path a line, kept in OUT: a later --overwrite
/// removes exactly these and nothing else.
inline constexpr const char* kSiteListingFileName = ".panoptes-site";

/// What export_site does with the database's files.
enum class DatabaseCopy {
  copy,  ///< copy the manifest, camera table and movies into OUT/db (self-contained site)
  link,  ///< OUT/db is a symbolic link to the database (no copy; the server must follow links)
};

/// Summary of an export.
struct SiteExport {
  std::int64_t streams = 0;         ///< streams in the database
  std::int64_t indexed = 0;         ///< streams whose fragment index was written
  std::int64_t bytes_copied = 0;    ///< movie and manifest bytes copied (0 when linked)
  /// A packed database: database.json's `stream_index` (packs, shards, entry size); null otherwise.
  nlohmann::json stream_index;
};

/// Writes OUT/index.html and the player's files, OUT/api/database.json, OUT/api/index/C/T.json per
/// stream (what `panoptes serve` computes per request), and the database under OUT/db. A packed
/// database gets no file per stream: its packs and pack indexes go to OUT/db/packs (hard links when
/// on the same file system, else copies) and one stream index per 65,536 streams to
/// OUT/api/streams/K.bin (web/stream_index.hpp), which database.json's `stream_index` describes. Missing or
/// unreadable movies get no index (the player shows its placeholder for them). The site is built in
/// a fresh staging directory beside OUT and moved in only when complete, so a failed export leaves
/// nothing behind, and nothing is ever written through a link found in OUT. Refuses an OUT that
/// exists and is not empty unless overwrite; then OUT must hold the listing of an earlier export
/// (kSiteListingFileName): exactly the files it lists are removed (a listed link is removed, never
/// followed) and an unlisted file where the new site needs a place is refused before OUT changes.
/// progress(done, total) is called now and then.
SiteExport export_site(const std::filesystem::path& database, const std::filesystem::path& out,
                       const std::filesystem::path& player_dir, DatabaseCopy mode, bool overwrite,
                       const std::function<void(std::int64_t, std::int64_t)>& progress = {});

}  // namespace panoptes::web
