#pragma once
// Removing only what a writer wrote. `--overwrite` replaces an old database (or exported site) in a
// directory that may also hold the user's own files (`holiday/precious.txt` next to
// `holiday/c{camera}/t{task}.mp4`) and links planted by anyone: it removes exactly the files the old
// manifest lists and the directories that become empty, never follows a link (a link at a listed
// name is removed itself, a link on the way to one is not entered), and leaves everything else.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace panoptes::store {

/// What an old manifest says about the files it owns, read from its JSON alone (its camera table
/// may be damaged). cameras/tasks < 0: unknown (no movie is then taken to be listed).
struct OldDatabaseFiles {
  std::string movie_pattern;  ///< empty: unreadable manifest
  std::int64_t cameras = -1, tasks = -1;
  std::string camera_table;  ///< the camera table file it references, or empty
  std::vector<std::string> packs;  ///< a packed database's pack and index files (relative paths)
};

/// Reads what the manifest `kManifestFileName` in `dirfd` lists (safe bounded read; never throws:
/// an unreadable manifest lists nothing). `display` names dirfd in messages.
OldDatabaseFiles describe_old_database(int dirfd, const std::filesystem::path& display);

/// The files under dirfd that `movie_pattern` names for some camera < cameras and task < tasks, found
/// by walking only the directories the pattern can name (so the work is bounded by what exists, not
/// by what a hostile manifest claims). Paths are relative, '/'-separated; links are listed, never entered.
std::vector<std::string> find_listed_movies(int dirfd, const std::string& movie_pattern, std::int64_t cameras,
                                            std::int64_t tasks);

/// Removes the files (or links: the link itself) at the `relative` paths under dirfd without following
/// any link on the way (a path through a link is skipped), then every parent directory of them that
/// is now empty, deepest first, up to but not including dirfd. Directories are never removed with
/// their contents. Missing files are skipped. Returns the number of files removed. Throws FileError
/// naming the path if a removal fails for another reason than "missing" or "not empty".
std::int64_t remove_owned_files(int dirfd, const std::vector<std::string>& relative,
                                const std::filesystem::path& display);

}  // namespace panoptes::store
