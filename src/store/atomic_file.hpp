#pragma once
// Durable, atomic replacement of a small file (the manifest and the camera table): a unique temp file in
// the same directory, fsync, rename over the target, fsync of the directory.
#include <filesystem>
#include <string_view>

namespace panoptes::store {

/// Writes `data` to `path` atomically: a reader sees either the previous file or the complete new one,
/// also after a crash. On failure (e.g. disk full) the temp file is removed, the previous file at `path`
/// is untouched and FileError is thrown (naming the file; `what` says which file it is, e.g. "manifest").
void write_file_atomic(const std::filesystem::path& path, std::string_view data, std::string_view what);

}  // namespace panoptes::store
