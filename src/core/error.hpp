#pragma once
// Errors raised by the Panoptes library. Messages name the file, the value and what was expected;
// the command line prints what() as one line and exits non-zero.
#include <stdexcept>
#include <string>

namespace panoptes {

/// Any error Panoptes reports about input, files or configuration.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An error about a file or directory; the message starts with the path.
class FileError : public Error {
 public:
  FileError(const std::string& path, const std::string& what) : Error(path + ": " + what), path_(path) {}
  /// The path the error is about.
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
};

/// Throws panoptes::Error(message) when condition is false.
inline void require(bool condition, const std::string& message) {
  if (!condition) throw Error(message);
}

}  // namespace panoptes
