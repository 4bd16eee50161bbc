#pragma once
// File access that never leaves a database directory. A database may come from a stranger: any name
// in it may be a symbolic link (to ~/.ssh/id_rsa, /etc/passwd, /dev/zero), a FIFO, a device or a
// file of gigabytes. Everything the store reads or writes inside a database goes through here:
// names are opened relative to the directory's descriptor (openat) without following links
// (O_NOFOLLOW on every component), without blocking (O_NONBLOCK: opening a FIFO returns at once),
// and must be regular files (fstat) of bounded size. The database directory itself is the user's
// choice and may be reached through links.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace panoptes::store {

/// An open file descriptor, closed on destruction.
class FileHandle {
 public:
  FileHandle() = default;
  explicit FileHandle(int fd) : fd_(fd) {}
  FileHandle(FileHandle&& o) noexcept : fd_(o.release()) {}
  FileHandle& operator=(FileHandle&& o) noexcept;
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  ~FileHandle();
  int get() const { return fd_; }
  /// Gives up ownership; returns the descriptor.
  int release();
  explicit operator bool() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

/// Opens the database directory `dir` (following links: the path is the caller's choice). Throws
/// FileError naming dir if it is missing or not a directory.
FileHandle open_directory(const std::filesystem::path& dir);

/// Opens (create = true: creates missing ones, mode 0755) the chain of directories `relative` (a
/// '/'-separated path of plain names, no "..") under `dirfd`, refusing any component that is a
/// symbolic link or not a directory. `display` is dirfd's path, for messages.
FileHandle open_subdirectory(int dirfd, std::string_view relative, bool create, const std::filesystem::path& display);

/// Opens the regular file `name` (a plain name) in `dirfd` for reading: no link followed, no
/// blocking, not larger than max_bytes. Returns an empty handle if it does not exist and
/// missing_ok; else throws FileError naming display/name and saying what it found instead
/// (a symbolic link, a FIFO, a device, a directory, a size over the limit). `what` names the file's
/// role in messages (e.g. "manifest").
FileHandle open_regular_file(int dirfd, const std::string& name, std::uint64_t max_bytes, std::string_view what,
                             const std::filesystem::path& display, bool missing_ok = false);

/// Reads the whole regular file `name` in `dirfd` (checks of open_regular_file). Throws FileError.
std::string read_regular_file(int dirfd, const std::string& name, std::uint64_t max_bytes, std::string_view what,
                              const std::filesystem::path& display);

/// Creates or opens for writing the regular file `name` in `dirfd`, never through a link (O_NOFOLLOW,
/// O_NONBLOCK, fstat: must be a regular file). truncate: empties it after the checks. Throws FileError.
FileHandle open_for_writing(int dirfd, const std::string& name, bool truncate, std::string_view what,
                            const std::filesystem::path& display);

/// Splits `path` into its parent directory (or "." when it has none) and file name.
std::pair<std::filesystem::path, std::string> split_parent(const std::filesystem::path& path);

}  // namespace panoptes::store
