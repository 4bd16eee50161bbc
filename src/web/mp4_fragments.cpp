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
    if (offset + n > size_) return false;
    in_.clear();
    in_.seekg(std::streamoff(offset));
    in_.read(static_cast<char*>(out), std::streamsize(n));
    return bool(in_);
  }

  /// The box header at offset inside [offset, end); false if it does not fit.
  bool box(std::uint64_t offset, std::uint64_t end, BoxHeader& h) {
    unsigned char b[16];
    if (offset + 8 > end || !read(offset, b, 8)) return false;
    std::memcpy(h.type.data(), b + 4, 4);
    h.size = be32(b);
    h.header = 8;
    if (h.size == 1) {
      if (offset + 16 > end || !read(offset + 8, b + 8, 8)) return false;
      h.size = be64(b + 8);
      h.header = 16;
    } else if (h.size == 0) {
      h.size = end - offset;  // "to the end of the file"
    }
    if (h.size < h.header)
      throw FileError(path_.string(), "box '" + std::string(h.type.data(), 4) + "' at byte " + std::to_string(offset) +
                                          " declares size " + std::to_string(h.size) + ", smaller than its header");
    return true;
  }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

bool is(const BoxHeader& h, const char* type) { return std::memcmp(h.type.data(), type, 4) == 0; }

/// Sum of trun sample counts over every traf of the moof at [begin, end).
std::uint64_t moof_samples(File& f, std::uint64_t begin, std::uint64_t end) {
  std::uint64_t samples = 0;
  bool found = false;
  BoxHeader traf;
  for (std::uint64_t p = begin; p < end && f.box(p, end, traf); p += traf.size) {
    if (!is(traf, "traf")) continue;
    const std::uint64_t traf_end = std::min(end, p + traf.size);
    BoxHeader child;
    for (std::uint64_t q = p + traf.header; q < traf_end && f.box(q, traf_end, child); q += child.size) {
      if (!is(child, "trun")) continue;
      unsigned char b[8];  // version + flags, sample_count
      if (!f.read(q + child.header, b, 8)) break;
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
  for (std::uint64_t p = 0; p < f.size() && f.box(p, f.size(), h); p += h.size) {
    if (p + h.size > f.size()) break;  // cut short: a fragment still being written
    if (is(h, "moov")) {
      have_moov = true;
      index.init_size = p + h.size;
    } else if (is(h, "moof")) {
      if (!have_moov) throw FileError(movie.string(), "a moof box comes before the moov box (not a Panoptes movie)");
      // The fragment is the moof plus the mdat right after it.
      BoxHeader mdat;
      const std::uint64_t q = p + h.size;
      if (!f.box(q, f.size(), mdat) || !is(mdat, "mdat") || q + mdat.size > f.size()) break;
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
