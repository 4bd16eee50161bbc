#include "web/stream_index.hpp"

#include <algorithm>
#include <cstring>

#include "core/error.hpp"

namespace panoptes::web {

namespace fs = std::filesystem;

namespace {

void put32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = std::uint8_t(v >> (8 * i));
}
void put64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = std::uint8_t(v >> (8 * i));
}
std::uint32_t get32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
std::uint64_t get64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

StreamIndexWriter::StreamIndexWriter(const fs::path& file, std::int64_t first_stream, std::int64_t streams,
                                     std::int64_t total_streams, int frames, int packs)
    : file_(file), first_(first_stream), streams_(streams), total_(total_streams), frames_(frames), packs_(packs) {
  if (packs > kStreamIndexMaxPacks)
    throw FileError(file.string(), std::to_string(packs) + " packs; a stream index names at most " +
                                       std::to_string(kStreamIndexMaxPacks));
  out_.open(file, std::ios::binary | std::ios::trunc);
  if (!out_) throw FileError(file.string(), "cannot create the stream index");
  const std::vector<char> header(kStreamIndexHeaderBytes, 0);  // written for real by finish()
  out_.write(header.data(), std::streamsize(header.size()));
}

void StreamIndexWriter::add(const StreamIndexEntry& e) {
  const std::int64_t stream = first_ + added_;
  if (added_ >= streams_) throw FileError(file_.string(), "more than " + std::to_string(streams_) + " entries added");
  if (e.fragments.size() > std::size_t(frames_))
    throw FileError(file_.string(), "stream " + std::to_string(stream) + " has " + std::to_string(e.fragments.size()) +
                                        " fragments; an entry holds at most " + std::to_string(frames_) + " (one per frame)");
  std::vector<std::uint8_t> b(stream_entry_bytes(frames_), 0);
  put32(&b[0], std::uint32_t(stream));
  put32(&b[4], std::uint32_t(e.fragments.size()));
  const auto check = [&](const StreamIndexEntry::Range& r, const char* what) {
    if (int(r.pack) >= packs_ || r.offset > kStreamIndexMaxOffset)
      throw FileError(file_.string(), "stream " + std::to_string(stream) + ": " + what + " in pack " + std::to_string(r.pack) +
                                          " at byte " + std::to_string(r.offset) + "; expected a pack below " +
                                          std::to_string(packs_) + " and an offset below 2^48");
  };
  if (!e.fragments.empty()) {
    check(e.init, "init segment");
    put32(&b[8], e.init.pack);
    put32(&b[12], e.init.size);
    put64(&b[16], e.init.offset);
  }
  put32(&b[24], std::uint32_t(e.damaged.size()));
  put32(&b[28], std::uint32_t(damaged_.size()));
  for (std::size_t k = 0; k < e.fragments.size(); ++k) {
    const auto& f = e.fragments[k];
    check(f, "fragment");
    std::uint8_t* p = &b[kStreamEntryHeaderBytes + kStreamFragmentBytes * k];
    put64(p, (std::uint64_t(f.pack) << 48) | f.offset);
    put32(p + 8, f.size);
    put32(p + 12, f.frames);
  }
  damaged_.insert(damaged_.end(), e.damaged.begin(), e.damaged.end());
  out_.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
  ++added_;
}

void StreamIndexWriter::finish() {
  if (added_ != streams_)
    throw FileError(file_.string(), std::to_string(added_) + " entries added; expected " + std::to_string(streams_));
  std::vector<std::uint8_t> tail(4 * damaged_.size());
  for (std::size_t k = 0; k < damaged_.size(); ++k) put32(&tail[4 * k], damaged_[k]);
  out_.write(reinterpret_cast<const char*>(tail.data()), std::streamsize(tail.size()));
  std::uint8_t h[kStreamIndexHeaderBytes] = {};
  std::memcpy(h, kStreamIndexMagic, 8);
  put32(h + 8, kStreamIndexVersion);
  put32(h + 12, kStreamIndexHeaderBytes);
  put32(h + 16, stream_entry_bytes(frames_));
  put32(h + 20, std::uint32_t(frames_));
  put64(h + 24, std::uint64_t(first_));
  put32(h + 32, std::uint32_t(streams_));
  put32(h + 36, std::uint32_t(packs_));
  put64(h + 40, std::uint64_t(total_));
  put64(h + 48, kStreamIndexHeaderBytes + std::uint64_t(streams_) * stream_entry_bytes(frames_));
  put32(h + 56, std::uint32_t(damaged_.size()));
  out_.seekp(0);
  out_.write(reinterpret_cast<const char*>(h), sizeof h);
  if (!out_.flush()) throw FileError(file_.string(), "cannot write the stream index");
  out_.close();
}

StreamIndexEntry read_stream_index_entry(const fs::path& file, std::int64_t stream) {
  std::ifstream in(file, std::ios::binary);
  std::uint8_t h[kStreamIndexHeaderBytes];
  if (!in.read(reinterpret_cast<char*>(h), sizeof h)) throw FileError(file.string(), "shorter than its 64-byte header");
  if (std::memcmp(h, kStreamIndexMagic, 8) != 0 || get32(h + 8) != kStreamIndexVersion)
    throw FileError(file.string(), "not a version-1 stream index (magic PNPTSTIX)");
  const std::uint32_t entry = get32(h + 16), slots = get32(h + 20);
  const std::uint64_t first = get64(h + 24), count = get32(h + 32), packs = get32(h + 36), damaged_at = get64(h + 48);
  if (entry != kStreamEntryHeaderBytes + kStreamFragmentBytes * std::uint64_t(slots))
    throw FileError(file.string(), "entry size " + std::to_string(entry) + " does not match " + std::to_string(slots) + " slots");
  if (stream < std::int64_t(first) || stream >= std::int64_t(first + count))
    throw FileError(file.string(), "holds streams " + std::to_string(first) + ".." + std::to_string(first + count - 1) +
                                       ", not " + std::to_string(stream));
  std::vector<std::uint8_t> b(entry);
  in.seekg(std::streamoff(kStreamIndexHeaderBytes + (std::uint64_t(stream) - first) * entry));
  if (!in.read(reinterpret_cast<char*>(b.data()), std::streamsize(entry)))
    throw FileError(file.string(), "entry of stream " + std::to_string(stream) + " cut short");
  if (get32(&b[0]) != std::uint32_t(stream))
    throw FileError(file.string(), "entry of stream " + std::to_string(stream) + " names stream " + std::to_string(get32(&b[0])));
  const std::uint32_t n = get32(&b[4]);
  if (n > slots) throw FileError(file.string(), "stream " + std::to_string(stream) + ": " + std::to_string(n) + " fragments in " + std::to_string(slots) + " slots");
  StreamIndexEntry e;
  e.init = {get32(&b[8]), get64(&b[16]), get32(&b[12]), 0};
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint8_t* p = &b[kStreamEntryHeaderBytes + kStreamFragmentBytes * k];
    const std::uint64_t where = get64(p);
    StreamIndexEntry::Range r{std::uint32_t(where >> 48), where & kStreamIndexMaxOffset, get32(p + 8), get32(p + 12)};
    if (r.pack >= packs || r.frames == 0)
      throw FileError(file.string(), "stream " + std::to_string(stream) + " fragment " + std::to_string(k) + ": pack " +
                                         std::to_string(r.pack) + " of " + std::to_string(packs) + ", " + std::to_string(r.frames) + " frames");
    e.fragments.push_back(r);
  }
  const std::uint32_t d = get32(&b[24]), at = get32(&b[28]);
  if (d > 0) {
    std::vector<std::uint8_t> list(4 * std::size_t(d));
    in.seekg(std::streamoff(damaged_at + 4 * std::uint64_t(at)));
    if (!in.read(reinterpret_cast<char*>(list.data()), std::streamsize(list.size())))
      throw FileError(file.string(), "damaged-frame list of stream " + std::to_string(stream) + " cut short");
    for (std::uint32_t k = 0; k < d; ++k) e.damaged.push_back(get32(&list[4 * k]));
  }
  return e;
}

}  // namespace panoptes::web
