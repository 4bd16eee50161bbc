#include "store/owned_files.hpp"
#include "store/pack.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <set>

#include "core/error.hpp"
#include "store/bounded_json.hpp"
#include "store/manifest.hpp"
#include "store/safe_file.hpp"

namespace panoptes::store {

namespace fs = std::filesystem;

OldDatabaseFiles describe_old_database(int dirfd, const fs::path& display) {
  OldDatabaseFiles old;
  nlohmann::json j;
  try {
    j = parse_bounded_json(read_regular_file(dirfd, kManifestFileName, kMaxManifestBytes, "manifest", display),
                           (display / kManifestFileName).string(), {}, "manifest");
  } catch (const std::exception&) {
    return old;  // unreadable or malformed: it lists nothing we could remove safely
  }
  if (!j.is_object()) return old;
  if (const auto t = j.find("camera_table"); t != j.end() && t->is_object()) {
    if (const auto n = t->find("cameras"); n != t->end() && n->is_number_integer()) old.cameras = n->get<std::int64_t>();
    if (const auto f = t->find("file"); f != t->end() && f->is_string()) {
      const std::string file = f->get<std::string>();
      // Only a plain name in the directory is ours to remove (never the manifest or the lock).
      if (!file.empty() && file.find('/') == std::string::npos && file != "." && file != ".." &&
          file != kManifestFileName && file.rfind(".panoptes", 0) != 0)
        old.camera_table = file;
    }
  } else if (const auto c = j.find("cameras"); c != j.end() && c->is_array()) {
    old.cameras = std::int64_t(c->size());
  }
  if (const auto t = j.find("tasks"); t != j.end() && t->is_array()) old.tasks = std::int64_t(t->size());
  if (const auto p = j.find("movie_pattern"); p != j.end() && p->is_string()) {
    try {
      validate_movie_pattern(p->get<std::string>());
      old.movie_pattern = p->get<std::string>();
    } catch (const Error&) {
      // An unsafe pattern lists no movie.
    }
  }
  // A packed database's packs: packs/s<segment>-r<rank>.pack and .idx of every segment it lists (at
  // most 10^6 names in all: a hostile manifest cannot make the overwrite walk more).
  if (const auto p = j.find("packs"); p != j.end() && p->is_array()) {
    for (const auto& seg : *p) {
      if (!seg.is_object()) continue;
      const auto s = seg.find("segment"), r = seg.find("ranks");
      if (s == seg.end() || r == seg.end() || !s->is_number_integer() || !r->is_number_integer()) continue;
      const std::int64_t segment = s->get<std::int64_t>(), ranks = r->get<std::int64_t>();
      if (segment < 0 || segment > 100000 || ranks < 1) continue;
      for (std::int64_t k = 0; k < ranks && old.packs.size() < 1000000; ++k) {
        old.packs.push_back(std::string(kPackDirectory) + "/" + pack_file_name(int(segment), int(k)));
        old.packs.push_back(std::string(kPackDirectory) + "/" + pack_index_name(int(segment), int(k)));
      }
    }
  }
  return old;
}

namespace {

// Parses a decimal number as std::to_string writes it (no sign, no leading zero) from name[pos, pos+len).
bool parse_index(const std::string& name, std::size_t pos, std::size_t len, std::int64_t limit, std::int64_t* out) {
  if (len == 0 || len > 18 || (len > 1 && name[pos] == '0')) return false;
  std::int64_t v = 0;
  for (std::size_t i = pos; i < pos + len; ++i) {
    if (name[i] < '0' || name[i] > '9') return false;
    v = v * 10 + (name[i] - '0');
  }
  if (v >= limit) return false;
  *out = v;
  return true;
}

struct Captures {
  std::int64_t camera = -1, task = -1;
};

// True if `name` matches the pattern component `part` (literal text with {camera} / {task}), with
// values consistent with those already captured (the pattern may name one twice).
bool match_component(const std::string& part, std::size_t pp, const std::string& name, std::size_t np,
                     std::int64_t cameras, std::int64_t tasks, Captures& cap) {
  if (pp == part.size()) return np == name.size();
  for (const auto& [key, limit, slot] : {std::tuple{std::string_view("{camera}"), cameras, &cap.camera},
                                         std::tuple{std::string_view("{task}"), tasks, &cap.task}}) {
    if (part.compare(pp, key.size(), key) != 0) continue;
    for (std::size_t len = 1; np + len <= name.size() && len <= 18; ++len) {
      std::int64_t v = 0;
      if (!parse_index(name, np, len, limit, &v)) {
        if (name[np + len - 1] < '0' || name[np + len - 1] > '9') break;
        continue;
      }
      if (*slot >= 0 && *slot != v) continue;
      const std::int64_t saved = *slot;
      *slot = v;
      if (match_component(part, pp + key.size(), name, np + len, cameras, tasks, cap)) return true;
      *slot = saved;
    }
    return false;
  }
  return np < name.size() && part[pp] == name[np] && match_component(part, pp + 1, name, np + 1, cameras, tasks, cap);
}

void walk(int dirfd, const std::vector<std::string>& parts, std::size_t depth, const std::string& prefix,
          std::int64_t cameras, std::int64_t tasks, const Captures& cap, std::vector<std::string>& out) {
  const std::string& part = parts[depth];
  const bool last = depth + 1 == parts.size();
  std::vector<std::pair<std::string, Captures>> names;
  if (part.find('{') == std::string::npos) {
    names.emplace_back(part, cap);  // a fixed name: no listing needed
  } else {
    const int fd = ::openat(dirfd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    DIR* d = ::fdopendir(fd);
    if (!d) {
      ::close(fd);
      return;
    }
    while (const dirent* e = ::readdir(d)) {
      const std::string name = e->d_name;
      Captures c = cap;
      if (match_component(part, 0, name, 0, cameras, tasks, c)) names.emplace_back(name, c);
    }
    ::closedir(d);
  }
  for (const auto& [name, c] : names) {
    struct stat st{};
    if (::fstatat(dirfd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) continue;
    if (last) {
      // A movie name must have been filled completely; a directory there is not a movie we wrote.
      if (c.camera >= 0 && c.task >= 0 && !S_ISDIR(st.st_mode)) out.push_back(prefix + name);
      continue;
    }
    if (!S_ISDIR(st.st_mode)) continue;  // links (and anything else) are never entered
    const int sub = ::openat(dirfd, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (sub < 0) continue;
    FileHandle h(sub);
    walk(sub, parts, depth + 1, prefix + name + "/", cameras, tasks, c, out);
  }
}

}  // namespace

std::vector<std::string> find_listed_movies(int dirfd, const std::string& movie_pattern, std::int64_t cameras,
                                            std::int64_t tasks) {
  std::vector<std::string> out;
  if (movie_pattern.empty() || cameras <= 0 || tasks <= 0) return out;
  try {
    validate_movie_pattern(movie_pattern);
  } catch (const Error&) {
    return out;
  }
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t end = movie_pattern.find('/', start);
    parts.push_back(movie_pattern.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  walk(dirfd, parts, 0, "", cameras, tasks, Captures{}, out);
  std::sort(out.begin(), out.end());
  return out;
}

std::int64_t remove_owned_files(int dirfd, const std::vector<std::string>& relative, const fs::path& display) {
  std::int64_t removed = 0;
  std::set<std::string> parents;
  for (const auto& path : relative) {
    const auto slash = path.rfind('/');
    const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash);
    const std::string name = path.substr(slash == std::string::npos ? 0 : slash + 1);
    if (name.empty() || name == "." || name == "..") continue;
    FileHandle parent;
    try {
      parent = open_subdirectory(dirfd, dir, false, display);
    } catch (const FileError&) {
      continue;  // gone, or reached through a link: nothing of ours is there
    }
    struct stat st{};
    if (::fstatat(parent.get(), name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) continue;
    if (S_ISDIR(st.st_mode)) continue;  // never a directory with its contents
    if (::unlinkat(parent.get(), name.c_str(), 0) != 0) {
      if (errno == ENOENT) continue;
      throw FileError((display / path).string(), std::string("cannot remove: ") + std::strerror(errno));
    }
    ++removed;
    for (std::string d = dir; !d.empty();) {
      parents.insert(d);
      const auto s = d.rfind('/');
      d = s == std::string::npos ? "" : d.substr(0, s);
    }
  }
  // Deepest first, so a parent is tried after its children; a directory holding anything else stays.
  std::vector<std::string> dirs(parents.begin(), parents.end());
  std::sort(dirs.begin(), dirs.end(), [](const std::string& a, const std::string& b) {
    const auto da = std::count(a.begin(), a.end(), '/'), db = std::count(b.begin(), b.end(), '/');
    return da != db ? da > db : a > b;
  });
  for (const auto& d : dirs) {
    const auto slash = d.rfind('/');
    FileHandle parent;
    try {
      parent = open_subdirectory(dirfd, slash == std::string::npos ? "" : d.substr(0, slash), false, display);
    } catch (const FileError&) {
      continue;
    }
    const std::string name = d.substr(slash == std::string::npos ? 0 : slash + 1);
    struct stat st{};
    if (::fstatat(parent.get(), name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISDIR(st.st_mode)) continue;
    ::unlinkat(parent.get(), name.c_str(), AT_REMOVEDIR);  // fails (and keeps it) unless empty
  }
  return removed;
}

}  // namespace panoptes::store
