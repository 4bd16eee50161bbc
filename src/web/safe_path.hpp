#pragma once
// Maps a URL path (already percent-decoded) to a file inside a root directory, refusing everything
// that could reach outside it: "..", ".", empty or hidden components, backslashes, NUL, and symbolic
// links that resolve outside the root.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace panoptes::web {

/// A root directory (canonical) that URL paths are resolved under.
class SafeRoot {
 public:
  /// Throws FileError if dir does not exist or is not a directory.
  explicit SafeRoot(const std::filesystem::path& dir);
  /// The regular file `relative` names inside the root, or nullopt (with `why` set) if the path is
  /// malformed, escapes the root lexically or through a link, or is not a regular file.
  std::optional<std::filesystem::path> resolve(std::string_view relative, std::string* why = nullptr) const;
  const std::filesystem::path& dir() const { return root_; }

 private:
  std::filesystem::path root_;
};

}  // namespace panoptes::web
