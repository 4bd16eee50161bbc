#include "core/file_read.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.hpp"

namespace panoptes {

namespace {

const char* kind_of(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::uint64_t open_checked(Fd& f, const std::string& path, std::uint64_t max_bytes, const std::string& what) {
  f.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (f.fd < 0) throw FileError(path, "cannot open the " + what + " (" + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw FileError(path, "cannot stat the " + what + " (" + std::strerror(errno) + ")");
  if (!S_ISREG(st.st_mode)) throw FileError(path, std::string("is ") + kind_of(st.st_mode) + "; expected a regular " + what);
  if (std::uint64_t(st.st_size) > max_bytes)
    throw FileError(path, what + " of " + std::to_string(st.st_size) + " bytes is larger than the limit of " +
                              std::to_string(max_bytes) + " bytes");
  return std::uint64_t(st.st_size);
}

}  // namespace

std::uint64_t regular_file_size(const std::string& path, std::uint64_t max_bytes, const std::string& what) {
  Fd f;
  return open_checked(f, path, max_bytes, what);
}

std::string read_regular_file(const std::string& path, std::uint64_t max_bytes, const std::string& what) {
  Fd f;
  const std::uint64_t size = open_checked(f, path, max_bytes, what);
  std::string data(size, '\0');
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(f.fd, data.data() + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw FileError(path, "cannot read the " + what + " (" + std::strerror(errno) + ")");
    if (n == 0) break;  // shrank while reading: keep what is there
    done += std::size_t(n);
  }
  data.resize(done);
  return data;
}

}  // namespace panoptes
