#include "web/site_export.hpp"

#include <fstream>

#include "core/error.hpp"
#include "store/database.hpp"
#include "web/database_json.hpp"
#include "web/mp4_fragments.hpp"
#include "web/safe_path.hpp"

namespace panoptes::web {

namespace fs = std::filesystem;

namespace {

void write_text(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out.flush()) throw FileError(path.string(), "cannot write");
}

std::int64_t copy_into(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  std::error_code ec;
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) throw FileError(to.string(), "cannot copy " + from.string() + ": " + ec.message());
  return std::int64_t(fs::file_size(to));
}

}  // namespace

SiteExport export_site(const fs::path& database, const fs::path& out, const fs::path& player_dir, DatabaseCopy mode,
                       bool overwrite, const std::function<void(std::int64_t, std::int64_t)>& progress) {
  const store::Database db = store::Database::open(database);
  const SafeRoot root(database);
  std::error_code ec;
  if (fs::exists(out) && !fs::is_empty(out, ec) && !overwrite)
    throw FileError(out.string(), "exists and is not empty (use --overwrite to replace the exported files)");
  if (fs::equivalent(root.dir(), out, ec) || (fs::exists(out) && fs::weakly_canonical(out).string().rfind(root.dir().string() + "/", 0) == 0))
    throw FileError(out.string(), "is inside the database directory; choose another output directory");
  fs::create_directories(out);

  // The player's files, as the server would serve them.
  for (const auto& entry : fs::recursive_directory_iterator(player_dir)) {
    if (!entry.is_regular_file()) continue;
    copy_into(entry.path(), out / entry.path().lexically_relative(player_dir));
  }
  write_text(out / "api" / "database.json", database_json(db).dump());

  SiteExport summary;
  summary.streams = db.stream_count();
  const fs::path db_out = out / "db";
  if (mode == DatabaseCopy::link) {
    if (fs::is_symlink(db_out) || fs::exists(db_out)) fs::remove_all(db_out);
    fs::create_directory_symlink(root.dir(), db_out);
  } else {
    summary.bytes_copied += copy_into(root.dir() / store::kManifestFileName, db_out / store::kManifestFileName);
    const std::string table = store::referenced_camera_table(root.dir() / store::kManifestFileName);
    if (!table.empty()) summary.bytes_copied += copy_into(root.dir() / table, db_out / table);
  }
  std::int64_t done = 0;
  for (int c = 0; c < db.camera_count(); ++c) {
    for (int t = 0; t < db.task_count(); ++t, ++done) {
      if (progress && done % 64 == 0) progress(done, summary.streams);
      const std::string relative = db.manifest().stream_relative_path(c, t);
      const auto movie = root.resolve(relative);
      if (!movie) continue;  // missing or unsafe: the player shows its placeholder
      FragmentIndex index;
      try {
        index = index_fragments(*movie);
      } catch (const Error&) {
        continue;  // unreadable: same
      }
      write_text(out / "api" / "index" / std::to_string(c) / (std::to_string(t) + ".json"),
                 fragment_index_json(index).dump());
      ++summary.indexed;
      if (mode == DatabaseCopy::copy) summary.bytes_copied += copy_into(*movie, db_out / relative);
    }
  }
  if (progress) progress(summary.streams, summary.streams);
  return summary;
}

}  // namespace panoptes::web
