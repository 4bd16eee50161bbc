#include "web/safe_path.hpp"

#include <cstdint>
#include <system_error>

#include "core/error.hpp"

namespace panoptes::web {

namespace fs = std::filesystem;

SafeRoot::SafeRoot(const fs::path& dir) {
  std::error_code ec;
  root_ = fs::canonical(dir, ec);
  if (ec || !fs::is_directory(root_)) throw FileError(dir.string(), "not a directory");
}

std::optional<fs::path> SafeRoot::resolve(std::string_view relative, std::string* why) const {
  auto refuse = [&](const std::string& reason) -> std::optional<fs::path> {
    if (why) *why = reason;
    return std::nullopt;
  };
  if (relative.empty()) return refuse("empty path");
  if (relative.find('\0') != std::string_view::npos || relative.find('\\') != std::string_view::npos)
    return refuse("NUL or backslash in the path");
  fs::path path = root_;
  std::size_t start = 0;
  while (start <= relative.size()) {
    const std::size_t slash = std::min(relative.find('/', start), relative.size());
    const std::string_view part = relative.substr(start, slash - start);
    // Hidden names too: the lock file, temporary manifests and dot-dirs are nobody's business.
    if (part.empty() || part.front() == '.') return refuse("empty, '.', '..' or hidden path component");
    path /= fs::path(std::string(part));
    start = slash + 1;
  }
  std::error_code ec;
  const fs::path real = fs::weakly_canonical(path, ec);
  if (ec) return refuse("cannot resolve the path");
  const auto rel = real.lexically_relative(root_);
  if (rel.empty() || *rel.begin() == "..") return refuse("resolves outside the served directory");
  if (!fs::is_regular_file(real, ec)) return refuse("no such file");
  return real;
}

store::FileHandle SafeRoot::open(std::string_view relative, std::string* why) const {
  const auto real = resolve(relative, why);
  if (!real) return {};
  // real is canonical and under root_: every component is a plain directory or the file itself.
  const fs::path rel = real->lexically_relative(root_);
  try {
    const store::FileHandle root = store::open_directory(root_);
    const store::FileHandle dir = store::open_subdirectory(root.get(), rel.parent_path().generic_string(), false, root_);
    return store::open_regular_file(dir.get(), rel.filename().string(), UINT64_MAX, "file", root_ / rel.parent_path());
  } catch (const Error& e) {
    if (why) *why = std::string("changed while being opened: ") + e.what();
    return {};
  }
}

}  // namespace panoptes::web
