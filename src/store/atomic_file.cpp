#include "store/atomic_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "store/safe_file.hpp"

namespace panoptes::store {

namespace {

void write_all(int fd, std::string_view data, const std::string& path) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw FileError(path, std::string("cannot write: ") + std::strerror(errno));
    }
    done += std::size_t(n);
  }
}

}  // namespace

void write_file_atomic(const std::filesystem::path& path, std::string_view data, std::string_view what) {
  // Everything relative to the directory's descriptor: the temp file is created exclusively without
  // following links (a link planted at a guessed temp name cannot redirect the write), and rename
  // replaces a link at the target name instead of writing through it.
  const auto [dir, name] = split_parent(path);
  FileHandle dfd;
  try {
    dfd = open_directory(dir);
  } catch (const FileError& e) {
    throw FileError(path.string(), "cannot create the " + std::string(what) + ": " + e.what());
  }
  // A unique temp name per writer: two processes writing at once must not share a temp file. Hidden
  // and starting with kTempPrefix, so one left by a killed writer is never taken for a movie (no
  // movie pattern may start with ".panoptes"), is not served, and the next writer removes it.
  const std::string tmp = kTempPrefix + name + ".tmp." + std::to_string(::getpid()) + "." +
                          std::to_string(std::random_device{}());
  const std::string tmp_name = (dir / tmp).string();
  const int fd = ::openat(dfd.get(), tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0)
    throw FileError(tmp_name, "cannot create the " + std::string(what) + ": " + std::strerror(errno));
  bool closed = false;
  try {
    write_all(fd, data, tmp_name);
    if (::fsync(fd) != 0) throw FileError(tmp_name, std::string("cannot sync: ") + std::strerror(errno));
    closed = true;  // close() releases the descriptor even when it reports an error
    if (::close(fd) != 0) throw FileError(tmp_name, std::string("cannot close: ") + std::strerror(errno));
  } catch (...) {
    if (!closed) ::close(fd);
    ::unlinkat(dfd.get(), tmp.c_str(), 0);
    throw;
  }
  if (::renameat(dfd.get(), tmp.c_str(), dfd.get(), name.c_str()) != 0) {
    const int err = errno;
    ::unlinkat(dfd.get(), tmp.c_str(), 0);
    throw FileError(path.string(), "cannot replace the " + std::string(what) + ": " + std::strerror(err));
  }
  // Make the rename itself durable (best effort: some file systems refuse fsync on directories).
  ::fsync(dfd.get());
}

std::int64_t remove_stale_temp_files(int dirfd) {
  const int fd = ::openat(dirfd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return 0;
  DIR* d = ::fdopendir(fd);
  if (!d) {
    ::close(fd);
    return 0;
  }
  std::vector<std::string> stale;
  const std::string prefix = kTempPrefix;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    // Also the visible names of earlier versions ("panoptes.json.tmp.<pid>.<n>").
    if ((name.rfind(prefix, 0) == 0 && name.find(".tmp.") != std::string::npos) ||
        name.rfind("panoptes.json.tmp.", 0) == 0)
      stale.push_back(name);
  }
  ::closedir(d);
  std::int64_t removed = 0;
  for (const auto& name : stale) {
    struct stat st{};
    if (::fstatat(dirfd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode)) continue;
    if (::unlinkat(dirfd, name.c_str(), 0) == 0) ++removed;
  }
  return removed;
}

}  // namespace panoptes::store
