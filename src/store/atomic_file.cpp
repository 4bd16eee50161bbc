#include "store/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <string>

#include "core/error.hpp"

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
  // A unique temp name per writer: two processes writing at once must not share a temp file.
  const std::filesystem::path tmp =
      path.string() + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(std::random_device{}());
  const std::string tmp_name = tmp.string();
  const int fd = ::open(tmp_name.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
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
    ::unlink(tmp_name.c_str());
    throw;
  }
  if (::rename(tmp_name.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp_name.c_str());
    throw FileError(path.string(), "cannot replace the " + std::string(what) + ": " + std::strerror(err));
  }
  // Make the rename itself durable (best effort: some file systems refuse fsync on directories).
  const std::string dir = path.has_parent_path() ? path.parent_path().string() : ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace panoptes::store
