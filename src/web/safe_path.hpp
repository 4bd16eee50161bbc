#pragma once
// Maps a URL path (already percent-decoded) to a file inside a root directory, refusing everything
// that could reach outside it: "..", ".", empty or hidden components, backslashes, NUL, and symbolic
// links that resolve outside the root. Files are then opened with the store's safe-open helpers
// (store/safe_file.hpp: openat relative to the root's descriptor, O_NOFOLLOW on every component), so
// a link swapped in between the check and the open is refused, never followed.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "store/safe_file.hpp"

namespace panoptes::web {

/// A root directory (canonical) that URL paths are resolved under.
class SafeRoot {
 public:
  /// Throws FileError if dir does not exist or is not a directory.
  explicit SafeRoot(const std::filesystem::path& dir);
  /// The regular file `relative` names inside the root, or nullopt (with `why` set) if the path is
  /// malformed, escapes the root lexically or through a link, or is not a regular file.
  std::optional<std::filesystem::path> resolve(std::string_view relative, std::string* why = nullptr) const;
  /// resolve(), then opens the resolved file for reading without following any link (a link that
  /// stays inside the root was resolved to its target's real path first). Empty handle (with `why`
  /// set) when resolve refuses or the file changed into a link, a non-file or vanished meanwhile.
  store::FileHandle open(std::string_view relative, std::string* why = nullptr) const;
  const std::filesystem::path& dir() const { return root_; }

 private:
  std::filesystem::path root_;
};

}  // namespace panoptes::web
