#include "web/site_export.hpp"

#include "player/keys_json.hpp"

#include <dirent.h>
#include <signal.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <map>
#include <set>

#include "core/error.hpp"
#include "store/database.hpp"
#include "store/owned_files.hpp"
#include "store/safe_file.hpp"
#include "web/database_json.hpp"
#include "web/mp4_fragments.hpp"
#include "web/safe_path.hpp"
#include "web/stream_index.hpp"

namespace panoptes::web {

namespace fs = std::filesystem;

namespace {

// The staging directory: everything is written into a fresh directory this run created (no link in
// it but the ones it makes), and moved into OUT only once the whole site is there.
class Staging {
 public:
  /// ".NAME.export-web.HOST.PID." : the staging directories of exports into NAME made on this host.
  static std::string prefix(const std::string& name) {
    char host[256] = {};
    if (::gethostname(host, sizeof host - 1) != 0 || !*host) std::snprintf(host, sizeof host, "localhost");
    for (char* c = host; *c; ++c)
      if (*c == '/' || *c == '.') *c = '_';
    return "." + name + ".export-web." + host + ".";
  }
  /// Removes the staging directories a killed export into NAME left beside it (issue 44: a SIGKILL left
  /// its hidden copy there for good): those of this host whose process no longer exists. Another
  /// host's (a shared file system) and a live export's are left alone.
  static void remove_dead(const fs::path& parent, const std::string& name) {
    const std::string pre = prefix(name);
    std::error_code ec;
    for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string file = it->path().filename().string();
      if (file.compare(0, pre.size(), pre) != 0 || !it->is_directory(ec) || it->is_symlink(ec)) continue;
      const std::string rest = file.substr(pre.size());
      const auto dot = rest.find('.');
      char* endp = nullptr;
      const long pid = std::strtol(rest.c_str(), &endp, 10);
      if (dot == std::string::npos || endp != rest.c_str() + dot || pid <= 0) continue;
      if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to ask): keep
      std::error_code rm;
      fs::remove_all(it->path(), rm);  // removes links themselves, never what they point to
    }
  }
  Staging(const fs::path& parent, const std::string& name) {
    remove_dead(parent, name);
    std::random_device rd;
    for (int attempt = 0;; ++attempt) {
      dir_ = parent / (prefix(name) + std::to_string(::getpid()) + "." + std::to_string(rd()));
      if (::mkdir(dir_.c_str(), 0700) == 0) break;
      if (errno != EEXIST || attempt > 8)
        throw FileError(dir_.string(), std::string("cannot create the staging directory: ") + std::strerror(errno));
    }
  }
  ~Staging() {
    std::error_code ec;
    fs::remove_all(dir_, ec);  // removes links themselves, never what they point to
  }
  Staging(const Staging&) = delete;
  Staging& operator=(const Staging&) = delete;
  const fs::path& dir() const { return dir_; }

  void write_text(const std::string& relative, const std::string& text) {
    const fs::path path = dir_ / relative;
    fs::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) throw FileError(path.string(), "cannot write");
    files_.push_back(relative);
  }

  std::int64_t copy_in(const fs::path& from, const std::string& relative) {
    const fs::path to = dir_ / relative;
    fs::create_directories(to.parent_path());
    std::error_code ec;
    fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
    if (ec) throw FileError(to.string(), "cannot copy " + from.string() + ": " + ec.message());
    files_.push_back(relative);
    return std::int64_t(fs::file_size(to));
  }

  /// A hard link to `from` when it is on the same file system (no bytes copied: packs are large and
  /// never rewritten once a manifest names them), else a copy. Returns the bytes copied (0 if linked).
  std::int64_t link_or_copy_in(const fs::path& from, const std::string& relative) {
    const fs::path to = dir_ / relative;
    fs::create_directories(to.parent_path());
    if (::link(from.c_str(), to.c_str()) == 0) {
      files_.push_back(relative);
      return 0;
    }
    return copy_in(from, relative);
  }

  void link(const fs::path& target, const std::string& relative) {
    fs::create_directory_symlink(target, dir_ / relative);
    files_.push_back(relative);
  }

  const std::vector<std::string>& files() const { return files_; }
  /// A file written into the staging directory by other means.
  void add_file(const std::string& relative) { files_.push_back(relative); }

 private:
  fs::path dir_;
  std::vector<std::string> files_;
};

// A listing line must name a plain relative path inside OUT.
bool plain_relative(const std::string& p) {
  if (p.empty() || p.front() == '/' || p.find('\0') != std::string::npos || p.find('\\') != std::string::npos)
    return false;
  for (std::size_t start = 0;;) {
    const std::size_t end = p.find('/', start);
    const std::string part = p.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (part.empty() || part == "." || part == "..") return false;
    if (end == std::string::npos) return true;
    start = end + 1;
  }
}

// The files a previous export listed in OUT; throws if OUT holds no listing (then it was not written
// by export-web, or by a version that did not list its files: nothing in it is known to be ours).
std::set<std::string> read_listing(int out_fd, const fs::path& out) {
  std::string text;
  try {
    text = store::read_regular_file(out_fd, kSiteListingFileName, std::uint64_t(256) << 20, "site listing", out);
  } catch (const FileError& e) {
    throw FileError(out.string(), "is not empty and holds no readable " + std::string(kSiteListingFileName) +
                                      " (the list of files an export-web wrote), so nothing in it is known to be ours "
                                      "to replace; remove it yourself or choose another output directory (" +
                                      e.what() + ")");
  }
  std::set<std::string> files;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.empty()) continue;
    if (!plain_relative(line) || line == kSiteListingFileName) continue;  // not ours to remove
    files.insert(std::move(line));
  }
  return files;
}

// True if the directory `relative` in OUT holds nothing but files the old listing owns (at any
// depth): removing them empties it, so it is pruned before the new file takes its place.
bool emptied_by_removal(int out_fd, const std::string& relative, const std::set<std::string>& owned, int depth = 0) {
  if (depth > 64) return false;
  const int fd = ::openat(out_fd, relative.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return false;
  DIR* d = ::fdopendir(fd);
  if (!d) {
    ::close(fd);
    return false;
  }
  std::vector<std::string> names;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name != "." && name != "..") names.push_back(name);
  }
  ::closedir(d);
  for (const auto& name : names) {
    const std::string path = relative + "/" + name;
    struct stat st{};
    if (::fstatat(out_fd, path.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) return false;
    if (S_ISDIR(st.st_mode) ? !emptied_by_removal(out_fd, path, owned, depth + 1) : !owned.count(path)) return false;
  }
  return true;
}

// Refuses, before anything in OUT changes, a new file whose place in OUT holds something the old
// listing does not own (the user's file, a link planted on the way, a directory).
void check_no_conflict(int out_fd, const fs::path& out, const std::vector<std::string>& files,
                       const std::set<std::string>& owned) {
  for (const auto& file : files) {
    std::string prefix;
    for (std::size_t start = 0;;) {
      const std::size_t end = file.find('/', start);
      const bool last = end == std::string::npos;
      prefix = file.substr(0, last ? std::string::npos : end);
      struct stat st{};
      if (::fstatat(out_fd, prefix.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) break;  // absent: free from here on
      const bool removed = S_ISDIR(st.st_mode) ? last && emptied_by_removal(out_fd, prefix, owned) : owned.count(prefix) > 0;
      if (last ? !removed : !(S_ISDIR(st.st_mode) || removed))
        throw FileError((out / prefix).string(),
                        "exists and was not written by export-web (it is not in " + std::string(kSiteListingFileName) +
                            "); refusing to replace it");
      if (last || !S_ISDIR(st.st_mode)) break;  // an owned file or link on the way: removed before the move
      start = end + 1;
    }
  }
}

// Moves the staged files into OUT one by one, creating directories without following links.
void move_in(const Staging& staging, int out_fd, const fs::path& out) {
  const store::FileHandle stage_fd = store::open_directory(staging.dir());
  std::vector<std::string> files = staging.files();
  files.push_back(kSiteListingFileName);
  for (const auto& file : files) {
    const auto slash = file.rfind('/');
    const std::string dir = slash == std::string::npos ? "" : file.substr(0, slash);
    const std::string name = file.substr(slash == std::string::npos ? 0 : slash + 1);
    const store::FileHandle from = store::open_subdirectory(stage_fd.get(), dir, false, staging.dir());
    const store::FileHandle to = store::open_subdirectory(out_fd, dir, true, out);
    if (::renameat(from.get(), name.c_str(), to.get(), name.c_str()) != 0)
      throw FileError((out / file).string(), std::string("cannot move the exported file in: ") + std::strerror(errno));
  }
}

// A database of movie files: per stream its fragment index as JSON (what serve computes per
// request) and, when copying, the movie.
void export_files(const store::Database& db, const SafeRoot& root, Staging& staging, DatabaseCopy mode,
                  SiteExport& summary, const std::function<void(std::int64_t, std::int64_t)>& progress) {
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
      nlohmann::json index_json = fragment_index_json(index);
      // Frames that fail the manifest's frame checks (checksum, identity, index, timestamp): the
      // browser decodes by itself, so the index says which ones to show as damaged.
      try {
        const std::vector<int> damaged = db.damaged_frames(c, t);
        if (!damaged.empty()) index_json["damaged_frames"] = damaged;
      } catch (const Error&) {
        // Truncated or not decodable here: the browser finds out by itself, as before.
      }
      staging.write_text("api/index/" + std::to_string(c) + "/" + std::to_string(t) + ".json", index_json.dump());
      ++summary.indexed;
      if (mode == DatabaseCopy::copy) summary.bytes_copied += staging.copy_in(*movie, "db/" + relative);
    }
  }
}

// A packed database: its packs (hard-linked or copied, with their indexes, so OUT/db stays a
// database) and the stream index shards (web/stream_index.hpp) instead of a JSON file per stream.
void export_packed(const store::Database& db, const SafeRoot& root, Staging& staging, DatabaseCopy mode,
                   SiteExport& summary, const std::function<void(std::int64_t, std::int64_t)>& progress) {
  // Packs are numbered in the manifest's order (segments, then ranks): known before any stream is read.
  std::map<std::string, std::uint32_t> number;  // pack file name -> position in the list
  nlohmann::json packs = nlohmann::json::array();
  for (const store::PackSegment& seg : db.manifest().packs) {
    for (int r = 0; r < seg.ranks; ++r) {
      const std::string name = store::pack_file_name(seg.segment, r);
      const std::string relative = std::string(store::kPackDirectory) + "/" + name;
      const auto pack = root.resolve(relative);
      if (!pack) continue;  // a rank that owned no camera wrote none
      number.emplace(name, std::uint32_t(packs.size()));
      packs.push_back("db/" + relative);
      if (mode == DatabaseCopy::copy) {
        summary.bytes_copied += staging.link_or_copy_in(*pack, "db/" + relative);
        const std::string index = std::string(store::kPackDirectory) + "/" + store::pack_index_name(seg.segment, r);
        if (const auto idx = root.resolve(index)) summary.bytes_copied += staging.link_or_copy_in(*idx, "db/" + index);
      }
    }
  }
  const int frames = db.frame_count(), tasks = db.task_count();
  const std::int64_t total = db.stream_count();
  nlohmann::json shards = nlohmann::json::array();
  for (std::int64_t first = 0; first < total; first += kStreamsPerShard) {
    const std::int64_t count = std::min(kStreamsPerShard, total - first);
    const std::string relative = "api/streams/" + std::to_string(first / kStreamsPerShard) + ".bin";
    fs::create_directories((staging.dir() / relative).parent_path());
    StreamIndexWriter writer(staging.dir() / relative, first, count, total, frames, int(packs.size()));
    for (std::int64_t s = first; s < first + count; ++s) {
      if (progress && s % 64 == 0) progress(s, total);
      const int c = int(s / tasks), t = int(s % tasks);
      StreamIndexEntry e;
      try {
        const store::PackedStream ps = db.packed_stream(c, t);
        const auto range = [&](const store::PackedStream::Piece& p) {
          const auto it = number.find(p.file.filename().string());
          if (it == number.end()) throw Error(p.file.string() + ": a pack the manifest does not list");
          return StreamIndexEntry::Range{it->second, p.offset, std::uint32_t(p.size), std::uint32_t(p.frames)};
        };
        for (std::size_t k = 1; k < ps.pieces.size() && ps.pieces[k].first_frame < frames; ++k)
          e.fragments.push_back(range(ps.pieces[k]));
        if (!e.fragments.empty()) e.init = range(ps.pieces.front());
      } catch (const Error&) {
        e.fragments.clear();  // a damaged index: the player shows its placeholder, as for a missing movie
      }
      if (!e.fragments.empty()) {
        ++summary.indexed;
        // Frames that fail the manifest's frame checks: the browser decodes by itself, so the index
        // says which ones to show as damaged (as api/index/C/T.json does for a files database).
        try {
          for (const int f : db.damaged_frames(c, t)) e.damaged.push_back(std::uint32_t(f));
        } catch (const Error&) {
          // Truncated or not decodable here: the browser finds out by itself.
        }
      }
      writer.add(e);
    }
    writer.finish();
    staging.add_file(relative);
    shards.push_back(relative);
  }
  summary.stream_index = {{"format", "panoptes stream index"},
                          {"version", kStreamIndexVersion},
                          {"packs", std::move(packs)},
                          {"shards", std::move(shards)},
                          {"streams_per_shard", kStreamsPerShard},
                          {"header_bytes", kStreamIndexHeaderBytes},
                          {"entry_bytes", stream_entry_bytes(frames)}};
}

}  // namespace

SiteExport export_site(const fs::path& database, const fs::path& out_arg, const fs::path& player_dir,
                       DatabaseCopy mode, bool overwrite, const std::function<void(std::int64_t, std::int64_t)>& progress) {
  const store::Database db = store::Database::open(database);
  const SafeRoot root(database);
  std::error_code ec;
  // OUT itself is the user's choice and may be reached through links; everything inside it is not.
  fs::path out = fs::weakly_canonical(fs::absolute(out_arg), ec);
  if (ec) throw FileError(out_arg.string(), "cannot resolve the output directory: " + ec.message());
  // "site/" names the directory site: without this its parent would be site itself, and the staging
  // directory would be made inside OUT.
  if (!out.has_filename()) out = out.parent_path();
  if (out == root.dir() || out.lexically_relative(root.dir()).begin()->string() != "..")
    throw FileError(out_arg.string(), "is inside the database directory; choose another output directory");
  const bool exists = fs::exists(out, ec);
  if (exists && !fs::is_directory(out, ec)) throw FileError(out_arg.string(), "exists and is not a directory");
  const bool empty = !exists || fs::is_empty(out, ec);
  if (!empty && !overwrite) {
    // --overwrite replaces only a previous export's files (its listing); advising it for a folder of
    // the user's own sent them in a circle (issue 44: the suggested option then refused too).
    if (fs::exists(out / kSiteListingFileName, ec))
      throw FileError(out_arg.string(), "holds an earlier export-web (use --overwrite to replace its files)");
    throw FileError(out_arg.string(), "exists, is not empty and was not written by export-web (no " +
                                          std::string(kSiteListingFileName) +
                                          "): choose another output directory, or an empty or new one");
  }
  fs::create_directories(out.parent_path(), ec);
  store::FileHandle out_fd;
  std::set<std::string> owned;
  if (!empty) {
    out_fd = store::open_directory(out);
    owned = read_listing(out_fd.get(), out_arg);
  }

  Staging staging(out.parent_path(), out.filename().string());
  // The player's files, as the server would serve them.
  for (const auto& entry : fs::recursive_directory_iterator(player_dir)) {
    if (!entry.is_regular_file()) continue;
    staging.copy_in(entry.path(), entry.path().lexically_relative(player_dir).generic_string());
  }
  staging.write_text("api/keys.json", player::keys_json(&db.manifest()).dump());

  SiteExport summary;
  summary.streams = db.stream_count();
  if (mode == DatabaseCopy::link) {
    staging.link(root.dir(), "db");
  } else {
    summary.bytes_copied += staging.copy_in(root.dir() / store::kManifestFileName, std::string("db/") + store::kManifestFileName);
    const std::string table = store::referenced_camera_table(root.dir() / store::kManifestFileName);
    if (!table.empty()) summary.bytes_copied += staging.copy_in(root.dir() / table, "db/" + table);
  }
  if (db.packed()) {
    export_packed(db, root, staging, mode, summary, progress);
  } else {
    export_files(db, root, staging, mode, summary, progress);
  }
  // After the streams: a packed site's database.json names the stream index written for them.
  nlohmann::json dbj = database_json(db);
  if (!summary.stream_index.is_null()) dbj["stream_index"] = summary.stream_index;
  staging.write_text("api/database.json", dbj.dump());
  std::string listing;
  for (const auto& f : staging.files()) listing += f + "\n";
  {
    std::ofstream l(staging.dir() / kSiteListingFileName, std::ios::binary | std::ios::trunc);
    l << listing;
    if (!l.flush()) throw FileError((staging.dir() / kSiteListingFileName).string(), "cannot write");
  }

  if (empty) {
    // A fresh OUT: the whole staged tree becomes it in one rename.
    if (exists && ::rmdir(out.c_str()) != 0)
      throw FileError(out_arg.string(), std::string("cannot replace the empty directory: ") + std::strerror(errno));
    if (::rename(staging.dir().c_str(), out.c_str()) != 0)
      throw FileError(out_arg.string(), std::string("cannot move the exported site in: ") + std::strerror(errno));
  } else {
    check_no_conflict(out_fd.get(), out_arg, staging.files(), owned);
    store::remove_owned_files(out_fd.get(), {owned.begin(), owned.end()}, out_arg);
    move_in(staging, out_fd.get(), out_arg);
  }
  if (progress) progress(summary.streams, summary.streams);
  return summary;
}

}  // namespace panoptes::web
