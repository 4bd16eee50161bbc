#pragma once
// Conversion between the two layouts of a database (`panoptes pack` / `panoptes unpack`): frames are
// copied as stored, never re-encoded, so every packet is bitwise the source's.
#include <cstdint>
#include <filesystem>
#include <functional>

namespace panoptes::store {

/// Called now and then with (streams done, streams in all).
using ConvertProgress = std::function<void(std::int64_t, std::int64_t)>;

/// Writes the files database `in` as a packed database at `out` (a new directory, or an empty one):
/// one pack (rank 0, segment 0) holding every stream's checkpointed frames as one fragment, the
/// manifest and camera table as the source's (layout packed). Every stream must have the same stream
/// header (one init segment serves all) and pass its checks. Throws Error/FileError naming the stream;
/// `out` is then left incomplete (no manifest is written before the pack is complete).
void pack_database(const std::filesystem::path& in, const std::filesystem::path& out, const ConvertProgress& progress = {});

/// Writes the packed database `in` as a files database at `out` (new or empty directory): each stream
/// becomes the file its movie pattern names, holding the pack's init segment and the stream's
/// fragments exactly as stored (a fragmented MP4 like MovieWriter's). Throws like pack_database.
void unpack_database(const std::filesystem::path& in, const std::filesystem::path& out,
                     const ConvertProgress& progress = {});

}  // namespace panoptes::store
