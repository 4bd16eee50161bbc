#pragma once
// Durable, atomic replacement of a small file (the manifest and the camera table): a unique temp file in
// the same directory, fsync, rename over the target, fsync of the directory.
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace panoptes::store {

/// Writes `data` to `path` atomically: a reader sees either the previous file or the complete new one,
/// also after a crash. On failure (e.g. disk full) the temp file is removed, the previous file at `path`
/// is untouched and FileError is thrown (naming the file; `what` says which file it is, e.g. "manifest").
void write_file_atomic(const std::filesystem::path& path, std::string_view data, std::string_view what);

/// Prefix of every temp file write_file_atomic makes (hidden; no movie pattern may start with it).
inline constexpr const char* kTempPrefix = ".panoptes-tmp.";

/// Removes the temp files write_file_atomic left in dirfd when a writer was killed between creating
/// and renaming one (regular files named kTempPrefix...; links and others are left alone). Call only
/// while holding the database's writer lock (no other writer's temp file can then be in flight).
/// Returns how many were removed.
std::int64_t remove_stale_temp_files(int dirfd);

}  // namespace panoptes::store
