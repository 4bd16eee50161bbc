#include "web/mp4_fragments.hpp"

#include <array>
#include <climits>
#include <cstring>
#include <fstream>
#include <string>

#include "core/error.hpp"

namespace panoptes::web {
namespace {

std::uint32_t be32(const unsigned char* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | std::uint32_t(p[3]);
}
std::uint64_t be64(const unsigned char* p) { return std::uint64_t(be32(p)) << 32 | be32(p + 4); }

std::string printable(const std::array<char, 4>& type);

struct BoxHeader {
  std::array<char, 4> type{};
  std::uint64_t size = 0;    // whole box, header included
  std::uint64_t header = 0;  // 8 or 16
};

class File {
 public:
  explicit File(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw FileError(path.string(), "cannot open the movie for reading");
    in_.seekg(0, std::ios::end);
    size_ = std::uint64_t(in_.tellg());
  }
  std::uint64_t size() const { return size_; }
  const std::filesystem::path& path() const { return path_; }

  /// Reads n bytes at offset; false if the file ends first.
  bool read(std::uint64_t offset, void* out, std::size_t n) {
    if (offset > size_ || n > size_ - offset) return false;
    in_.clear();
    in_.seekg(std::streamoff(offset));
    in_.read(static_cast<char*>(out), std::streamsize(n));
    return bool(in_);
  }

  /// The box header at offset inside [offset, end); false if its header does not fit. A box that
  /// declares more bytes than [offset, end) holds is, with `overhang_ends`, a box cut short (a movie
  /// still being written: false), else an error. Sizes are compared as `size > end - offset`, never
  /// by adding them to the offset: a 64-bit size near 2^64 must not wrap around to a small offset
  /// (issue 31: 2^64-16 sent the walk backwards, forever).
  bool box(std::uint64_t offset, std::uint64_t end, BoxHeader& h, bool overhang_ends = false) {
    unsigned char b[16];
    if (offset >= end || end - offset < 8 || !read(offset, b, 8)) return false;
    std::memcpy(h.type.data(), b + 4, 4);
    h.size = be32(b);
    h.header = 8;
    if (h.size == 1) {
      if (end - offset < 16 || !read(offset + 8, b + 8, 8)) return false;
      h.size = be64(b + 8);
      h.header = 16;
    } else if (h.size == 0) {
      h.size = end - offset;  // "to the end of the file"
    }
    if (h.size < h.header)
      throw FileError(path_.string(), "box '" + printable(h.type) + "' at byte " + std::to_string(offset) +
                                          " declares size " + std::to_string(h.size) + ", smaller than its header");
    if (h.size > end - offset) {
      if (overhang_ends) return false;
      throw FileError(path_.string(), "box '" + printable(h.type) + "' at byte " + std::to_string(offset) +
                                          " declares size " + std::to_string(h.size) + ", beyond its parent's end at byte " +
                                          std::to_string(end) + " (expected at most " + std::to_string(end - offset) + ")");
    }
    return true;
  }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

/// A box type for a message: its four bytes, with anything unprintable as '?'.
std::string printable(const std::array<char, 4>& type) {
  std::string s(type.data(), 4);
  for (char& c : s)
    if (c < 0x20 || c > 0x7e) c = '?';
  return s;
}

bool is(const BoxHeader& h, const char* type) { return std::memcmp(h.type.data(), type, 4) == 0; }

/// Sum of trun sample counts over every traf of the moof at [begin, end).
std::uint64_t moof_samples(File& f, std::uint64_t begin, std::uint64_t end) {
  std::uint64_t samples = 0;
  bool found = false;
  BoxHeader traf;
  for (std::uint64_t p = begin; p < end && f.box(p, end, traf); p += traf.size) {
    if (!is(traf, "traf")) continue;
    const std::uint64_t traf_end = p + traf.size;  // inside [begin, end): File::box checked it
    BoxHeader child;
    for (std::uint64_t q = p + traf.header; q < traf_end && f.box(q, traf_end, child); q += child.size) {
      if (!is(child, "trun")) continue;
      unsigned char b[8];  // version + flags, sample_count
      if (child.size - child.header < 8 || !f.read(q + child.header, b, 8))
        throw FileError(f.path().string(), "trun box at byte " + std::to_string(q) + " of " + std::to_string(child.size) +
                                               " bytes is too short for its sample count (expected at least " +
                                               std::to_string(child.header + 8) + ")");
      samples += be32(b + 4);
      found = true;
    }
  }
  if (!found) throw FileError(f.path().string(), "fragment at byte " + std::to_string(begin) + " has no trun box");
  return samples;
}

}  // namespace

FragmentIndex index_fragments(const std::filesystem::path& movie) {
  File f(movie);
  FragmentIndex index;
  index.file_size = f.size();
  bool have_moov = false;
  int next_frame = 0;
  BoxHeader h;
  // Every box is at least 8 bytes and lies inside the file (File::box), so the walk takes at most
  // file size / 8 steps whatever the sizes claim.
  for (std::uint64_t p = 0; p < f.size() && f.box(p, f.size(), h, /*overhang_ends=*/true); p += h.size) {
    if (is(h, "moov")) {
      // One init segment, before every fragment: a second moov would make [0, init_size) swallow the
      // fragments before it (found by fuzz/mp4_fragments_fuzz.cpp).
      if (have_moov)
        throw FileError(movie.string(), "a second moov box at byte " + std::to_string(p) + " (not a Panoptes movie)");
      have_moov = true;
      index.init_size = p + h.size;
    } else if (is(h, "moof")) {
      if (!have_moov) throw FileError(movie.string(), "a moof box comes before the moov box (not a Panoptes movie)");
      // The fragment is the moof plus the mdat right after it.
      BoxHeader mdat;
      const std::uint64_t q = p + h.size;
      // An mdat running past the end of the file: the fragment is still being written.
      if (!f.box(q, f.size(), mdat, /*overhang_ends=*/true) || !is(mdat, "mdat")) break;
      const std::uint64_t count = moof_samples(f, p + h.header, p + h.size);
      // A hostile trun count must not overflow the frame numbers: every sample takes at least one byte.
      if (count > mdat.size || count > std::uint64_t(INT_MAX - next_frame))
        throw FileError(movie.string(), "fragment at byte " + std::to_string(p) + " claims " + std::to_string(count) +
                                            " samples in an mdat of " + std::to_string(mdat.size) +
                                            " bytes (expected at most one sample per byte)");
      const int n = int(count);
      index.fragments.push_back({p, h.size + mdat.size, next_frame, n});
      next_frame += n;
      h.size += mdat.size;
    }
  }
  if (!have_moov) throw FileError(movie.string(), "no moov box: not an MP4 movie");
  return index;
}

}  // namespace panoptes::web
