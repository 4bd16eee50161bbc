#include "store/safe_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "core/error.hpp"

namespace panoptes::store {

namespace fs = std::filesystem;

FileHandle& FileHandle::operator=(FileHandle&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = o.release();
  }
  return *this;
}

FileHandle::~FileHandle() {
  if (fd_ >= 0) ::close(fd_);
}

int FileHandle::release() {
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

namespace {

// What a non-regular file is, for messages.
std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

// Describes why openat(..., O_NOFOLLOW) failed on `name`: ELOOP means it is a link.
std::string open_failure(int dirfd, const std::string& name, int err) {
  struct stat st{};
  if ((err == ELOOP || err == ENOTDIR || err == ENXIO) && ::fstatat(dirfd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0)
    return "is " + kind_of(st.st_mode) + ", not a regular file; refused (a database never points outside itself)";
  return std::strerror(err);
}

std::string at(const fs::path& display, const std::string& name) { return (display / name).string(); }

}  // namespace

FileHandle open_directory(const fs::path& dir) {
  const std::string d = dir.empty() ? std::string(".") : dir.string();
  const int fd = ::open(d.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) throw FileError(d, "no such directory");
    if (err == ENOTDIR) throw FileError(d, "not a directory");
    throw FileError(d, std::string("cannot open the directory: ") + std::strerror(err));
  }
  return FileHandle(fd);
}

FileHandle open_subdirectory(int dirfd, std::string_view relative, bool create, const fs::path& display) {
  FileHandle current(::fcntl(dirfd, F_DUPFD_CLOEXEC, 0));
  if (!current) throw FileError(display.string(), std::string("cannot open: ") + std::strerror(errno));
  fs::path shown = display;
  std::size_t start = 0;
  while (start < relative.size()) {
    std::size_t end = relative.find('/', start);
    if (end == std::string_view::npos) end = relative.size();
    const std::string part(relative.substr(start, end - start));
    start = end + 1;
    if (part.empty() || part == ".") continue;
    if (part == "..") throw FileError((shown / part).string(), "\"..\" is not allowed inside a database");
    if (create && ::mkdirat(current.get(), part.c_str(), 0755) != 0 && errno != EEXIST)
      throw FileError((shown / part).string(), std::string("cannot create the directory: ") + std::strerror(errno));
    const int fd = ::openat(current.get(), part.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) {
      const int err = errno;
      throw FileError((shown / part).string(), err == ENOENT ? std::string("no such directory")
                                                             : open_failure(current.get(), part, err));
    }
    current = FileHandle(fd);
    shown /= part;
  }
  return current;
}

FileHandle open_regular_file(int dirfd, const std::string& name, std::uint64_t max_bytes, std::string_view what,
                             const fs::path& display, bool missing_ok) {
  // Look before opening: opening a device can have side effects (a tape rewinds, a modem hangs up).
  struct stat pre{};
  if (::fstatat(dirfd, name.c_str(), &pre, AT_SYMLINK_NOFOLLOW) == 0 && !S_ISREG(pre.st_mode))
    throw FileError(at(display, name), "the " + std::string(what) + " is " + kind_of(pre.st_mode) +
                                           ", not a regular file; refused (a database never points outside itself)");
  const int fd = ::openat(dirfd, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT && missing_ok) return {};
    if (err == ENOENT) throw FileError(at(display, name), std::string(what) + " missing");
    throw FileError(at(display, name), "cannot read the " + std::string(what) + ": " + open_failure(dirfd, name, err));
  }
  FileHandle h(fd);
  struct stat st{};
  if (::fstat(fd, &st) != 0)
    throw FileError(at(display, name), "cannot read the " + std::string(what) + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw FileError(at(display, name), "the " + std::string(what) + " is " + kind_of(st.st_mode) +
                                           ", not a regular file; refused");
  if (std::uint64_t(st.st_size) > max_bytes)
    throw FileError(at(display, name), "the " + std::string(what) + " has " + std::to_string(st.st_size) +
                                           " bytes, more than the limit of " + std::to_string(max_bytes) + "; refused");
  // Reads of a regular file never block; clearing O_NONBLOCK keeps read() semantics plain.
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  return h;
}

std::string read_regular_file(int dirfd, const std::string& name, std::uint64_t max_bytes, std::string_view what,
                              const fs::path& display) {
  FileHandle h = open_regular_file(dirfd, name, max_bytes, what, display);
  struct stat st{};
  ::fstat(h.get(), &st);
  std::string bytes(std::size_t(st.st_size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(h.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      throw FileError(at(display, name), "cannot read the " + std::string(what) + ": " + std::strerror(errno));
    if (n == 0) break;  // it shrank while we read: the caller's parser reports what is missing
    done += std::size_t(n);
  }
  bytes.resize(done);
  return bytes;
}

FileHandle open_for_writing(int dirfd, const std::string& name, bool truncate, std::string_view what,
                            const fs::path& display) {
  struct stat pre{};
  if (::fstatat(dirfd, name.c_str(), &pre, AT_SYMLINK_NOFOLLOW) == 0 && !S_ISREG(pre.st_mode))
    throw FileError(at(display, name), "the " + std::string(what) + " is " + kind_of(pre.st_mode) +
                                           ", not a regular file; refused (a database never points outside itself)");
  const int fd = ::openat(dirfd, name.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC | O_NOCTTY, 0644);
  if (fd < 0) {
    const int err = errno;
    throw FileError(at(display, name), "cannot create the " + std::string(what) + ": " + open_failure(dirfd, name, err));
  }
  FileHandle h(fd);
  struct stat st{};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    throw FileError(at(display, name), "the " + std::string(what) + " is " + kind_of(st.st_mode) +
                                           ", not a regular file; refused");
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  if (truncate && ::ftruncate(fd, 0) != 0)
    throw FileError(at(display, name), "cannot truncate the " + std::string(what) + ": " + std::strerror(errno));
  return h;
}

std::pair<fs::path, std::string> split_parent(const fs::path& path) {
  return {path.has_parent_path() ? path.parent_path() : fs::path("."), path.filename().string()};
}

}  // namespace panoptes::store
