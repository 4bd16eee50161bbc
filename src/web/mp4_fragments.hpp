#pragma once
// Where the fragments of a fragmented MP4 lie, so a browser can fetch one fragment (moof + mdat) with
// one byte-range request instead of the whole movie. Panoptes movies are written with
// frag_keyframe + empty_moov (docs/formats.md): an init segment (ftyp + moov without samples) and
// then fragments that each start with a keyframe.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace panoptes::web {

/// One fragment: bytes [offset, offset + size) hold a moof and its mdat; it carries `frames` samples
/// starting at frame `first_frame` (frames are counted from the start of the movie).
struct Fragment {
  std::uint64_t offset = 0, size = 0;
  int first_frame = 0, frames = 0;
};

/// The layout of one movie: the init segment is bytes [0, init_size).
struct FragmentIndex {
  std::uint64_t file_size = 0;
  std::uint64_t init_size = 0;
  std::vector<Fragment> fragments;
  /// Frames in complete fragments.
  int frame_count() const { return fragments.empty() ? 0 : fragments.back().first_frame + fragments.back().frames; }
};

/// Reads only the box headers (and each moof's trun sample counts) of the movie, a few hundred bytes
/// per fragment. A fragment cut short at the end of the file (a movie still being written, or
/// truncated) is left out. Throws FileError if the file cannot be read or is not a fragmented MP4
/// (no moov before the first moof, a moof without trun, a box size that makes no sense).
FragmentIndex index_fragments(const std::filesystem::path& movie);

}  // namespace panoptes::web
