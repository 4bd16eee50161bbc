#include "video/mp4_table_check.hpp"

#include <unistd.h>

#include <cstring>

#include "core/error.hpp"

namespace panoptes::video {

namespace {

std::uint64_t be(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

struct Walker {
  const ReadAt& pread;
  std::int64_t size;
  const std::string& path;
  std::uint64_t samples = 0;  // declared by every trun / stsz / stz2 so far

  bool read(std::int64_t pos, std::uint8_t* buf, int n) const {
    if (pos < 0 || pos + n > size) return false;
    for (int done = 0; done < n;) {
      const std::int64_t got = pread(buf + done, std::size_t(n - done), pos + done);
      if (got <= 0) return false;
      done += int(got);
    }
    return true;
  }

  [[noreturn]] void refuse(const char* type, std::int64_t at, const std::string& what) const {
    throw FileError(path, std::string("not a readable movie: MP4 box '") + type + "' at byte " +
                              std::to_string(at) + " " + what);
  }

  // A table of `count` entries of `entry` bytes each, starting `header` bytes into the payload.
  void table_fits(const char* type, std::int64_t at, std::uint64_t payload, std::uint64_t header,
                  std::uint64_t count, std::uint64_t entry) const {
    if (count == 0) return;
    if (header > payload || (entry > 0 && count > (payload - header) / entry))
      refuse(type, at, "declares " + std::to_string(count) + " entries of " + std::to_string(entry) +
                           " bytes but holds only " + std::to_string(payload > header ? payload - header : 0) +
                           " bytes of table");
  }

  void add_samples(const char* type, std::int64_t at, std::uint64_t count) {
    samples += count;
    if (samples > std::uint64_t(size))
      refuse(type, at, "declares " + std::to_string(count) + " samples: with the tables before it, " +
                           std::to_string(samples) + " samples, more than the file's " + std::to_string(size) +
                           " bytes of MP4 boxes can hold (each sample needs at least one byte)");
  }

  void leaf(const char* type, std::int64_t at, std::int64_t body, std::uint64_t payload) {
    // FFmpeg cuts a box to its parent but then reads a table's header fields whether or not they lie
    // inside the box (a 7-byte trun still has its sample count read from the bytes after it), so the
    // fields come from the file and only the table is held to the box.
    std::uint8_t h[20] = {};
    const std::int64_t in_file = size - body;
    const int want = int(in_file < std::int64_t(sizeof h) ? in_file : std::int64_t(sizeof h));
    if (want < 8 || !read(body, h, want)) return;  // not even a count left in the file
    const int version = h[0];
    const std::uint32_t flags = std::uint32_t(be(h + 1, 3));
    const std::uint64_t count = be(h + 4, 4);
    auto is = [&](const char* t) { return std::memcmp(type, t, 4) == 0; };
    if (is("stts") || is("ctts")) {
      table_fits(type, at, payload, 8, count, 8);
    } else if (is("stss") || is("stco")) {
      table_fits(type, at, payload, 8, count, 4);
    } else if (is("stsc")) {
      table_fits(type, at, payload, 8, count, 12);
    } else if (is("co64")) {
      table_fits(type, at, payload, 8, count, 8);
    } else if (is("elst")) {
      table_fits(type, at, payload, 8, count, version == 1 ? 20 : 12);
    } else if (is("trun")) {
      // Optional fields: data offset, first sample flags; per sample: duration, size, flags, cto.
      const std::uint64_t header = 8 + (flags & 0x1 ? 4 : 0) + (flags & 0x4 ? 4 : 0);
      const std::uint64_t entry = (flags & 0x100 ? 4 : 0) + (flags & 0x200 ? 4 : 0) + (flags & 0x400 ? 4 : 0) +
                                  (flags & 0x800 ? 4 : 0);
      table_fits(type, at, payload, header, count, entry);
      add_samples(type, at, count);
    } else if (is("stsz")) {
      if (want < 12) return;
      const std::uint64_t sample_size = be(h + 4, 4), n = be(h + 8, 4);
      table_fits(type, at, payload, 12, n, sample_size == 0 ? 4 : 0);
      add_samples(type, at, n);
    } else if (is("stz2")) {
      if (want < 12) return;
      const std::uint64_t field_bits = h[7], n = be(h + 8, 4);
      // 4-, 8- or 16-bit sizes: compare bits to keep 4-bit tables exact.
      if (n > 0 && (field_bits == 4 || field_bits == 8 || field_bits == 16))
        if (payload < 12 || n > (payload - 12) * 8 / field_bits)
          refuse(type, at, "declares " + std::to_string(n) + " sample sizes but holds only " +
                               std::to_string(payload > 12 ? payload - 12 : 0) + " bytes of table");
      add_samples(type, at, n);
    } else if (is("sbgp")) {
      // grouping_type, (v1) grouping_type_parameter, entry_count; 8-byte entries. FFmpeg allocates the
      // whole table from the count before reading it.
      const std::uint64_t header = version == 1 ? 12 : 8;
      if (std::uint64_t(want) < header + 4) return;
      table_fits(type, at, payload, header + 4, be(h + header, 4), 8);
    } else if (is("tfra")) {
      if (want < 16) return;
      const std::uint64_t lengths = be(h + 8, 4), n = be(h + 12, 4);
      const std::uint64_t entry = (version == 1 ? 16 : 8) + ((lengths >> 4) & 3) + 1 + ((lengths >> 2) & 3) + 1 +
                                  (lengths & 3) + 1;
      table_fits(type, at, payload, 16, n, entry);
    }
  }

  // Boxes in [begin, end): containers are entered, tables checked, anything else skipped.
  void walk(std::int64_t begin, std::int64_t end, int depth) {
    if (depth > 16) return;  // FFmpeg stops nesting far earlier
    std::int64_t pos = begin;
    std::uint8_t h[16];
    while (end - pos >= 8) {
      if (!read(pos, h, 8)) return;
      std::uint64_t box = be(h, 4);
      std::int64_t header = 8;
      if (box == 1) {
        if (end - pos < 16 || !read(pos, h, 16)) return;
        box = be(h + 8, 8);
        header = 16;
      } else if (box == 0) {
        box = std::uint64_t(end - pos);  // to the end of its parent
      }
      if (box < std::uint64_t(header)) return;  // FFmpeg stops here too
      // A box claiming more than its parent is cut to it: FFmpeg reads what is there.
      if (box > std::uint64_t(end - pos)) box = std::uint64_t(end - pos);
      char type[5] = {char(h[4]), char(h[5]), char(h[6]), char(h[7]), 0};
      const std::int64_t body = pos + header;
      const std::uint64_t payload = box - std::uint64_t(header);
      static constexpr const char* kContainers[] = {"moov", "trak", "mdia", "minf", "stbl", "edts",
                                                    "mvex", "moof", "traf", "mfra"};
      bool container = false;
      for (const char* c : kContainers) container = container || std::memcmp(type, c, 4) == 0;
      if (container)
        walk(body, body + std::int64_t(payload), depth + 1);
      else
        leaf(type, pos, body, payload);
      pos += std::int64_t(box);
    }
  }
};

}  // namespace

void check_mp4_sample_tables(int fd, std::int64_t size, const std::string& path) {
  const ReadAt read = [fd](std::uint8_t* buf, std::size_t n, std::int64_t pos) {
    return std::int64_t(::pread(fd, buf, n, pos));
  };
  check_mp4_sample_tables(read, size, path);
}

void check_mp4_sample_tables(const ReadAt& read, std::int64_t size, const std::string& path) {
  Walker w{read, size, path};
  w.walk(0, size, 0);
}

}  // namespace panoptes::video
