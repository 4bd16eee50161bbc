#include "store/pack.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/error.hpp"
#include "store/camera_table.hpp"

namespace panoptes::store {

namespace fs = std::filesystem;

namespace {

void put_le(std::uint8_t* p, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) p[i] = std::uint8_t(v >> (8 * i));
}
std::uint64_t get_le(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

void write_all(int fd, const std::uint8_t* data, std::size_t size, std::uint64_t at, const fs::path& path) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pwrite(fd, data + done, size - done, off_t(at + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw FileError(path.string(), std::string("cannot write: ") + (n < 0 ? std::strerror(errno) : "no progress"));
    done += std::size_t(n);
  }
}

bool read_all(int fd, std::uint8_t* data, std::size_t size, std::uint64_t at) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pread(fd, data + done, size - done, off_t(at + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += std::size_t(n);
  }
  return true;
}

void encode_record(std::uint8_t* p, const PackRecord& r, std::uint32_t stream) {
  put_le(p, r.offset, 8);
  put_le(p + 8, r.size, 4);
  put_le(p + 12, r.first_frame, 4);
  put_le(p + 16, r.frames, 4);
  put_le(p + 20, pack_record_check(r, stream), 4);
}

std::uint64_t header_bytes_for(std::size_t cameras) { return (kPackIndexHeaderFixed + 4 * cameras + 7) / 8 * 8; }

}  // namespace

std::string pack_file_name(int segment, int rank) {
  return "s" + std::to_string(segment) + "-r" + std::to_string(rank) + ".pack";
}
std::string pack_index_name(int segment, int rank) {
  return "s" + std::to_string(segment) + "-r" + std::to_string(rank) + ".idx";
}

std::uint32_t pack_record_check(const PackRecord& r, std::uint32_t stream) {
  std::uint8_t b[24];
  put_le(b, r.offset, 8);
  put_le(b + 8, r.size, 4);
  put_le(b + 12, r.first_frame, 4);
  put_le(b + 16, r.frames, 4);
  put_le(b + 20, stream, 4);
  return crc32(b, sizeof b);
}

// --- writer ---

PackWriter::PackWriter(int packs_dir_fd, const fs::path& packs_dir, int segment, int rank, std::vector<int> cameras,
                       int tasks, int first_frame, const std::vector<std::uint8_t>& init, std::uint32_t timescale,
                       std::uint32_t frame_ticks)
    : cameras_(std::move(cameras)), tasks_(tasks) {
  std::sort(cameras_.begin(), cameras_.end());
  const std::string pack_name = pack_file_name(segment, rank), index_name = pack_index_name(segment, rank);
  pack_path_ = packs_dir / pack_name;
  index_path_ = packs_dir / index_name;
  pack_ = open_for_writing(packs_dir_fd, pack_name, true, "pack", packs_dir);
  index_ = open_for_writing(packs_dir_fd, index_name, true, "pack index", packs_dir);
  // The pack begins with the init segment every stream of it shares (one configuration per database).
  write_all(pack_.get(), init.data(), init.size(), 0, pack_path_);
  end_ = init.size();
  std::vector<std::uint8_t> h(header_bytes_for(cameras_.size()), 0);
  std::memcpy(h.data(), kPackIndexMagic, 8);
  put_le(&h[8], kPackIndexVersion, 4);
  put_le(&h[12], h.size(), 4);
  put_le(&h[16], std::uint32_t(segment), 4);
  put_le(&h[20], std::uint32_t(rank), 4);
  put_le(&h[24], cameras_.size(), 4);
  put_le(&h[28], std::uint32_t(tasks), 4);
  put_le(&h[32], std::uint32_t(first_frame), 4);
  put_le(&h[36], timescale, 4);
  put_le(&h[40], frame_ticks, 4);
  put_le(&h[44], init.size(), 4);
  put_le(&h[48], 0, 8);  // init offset
  for (std::size_t i = 0; i < cameras_.size(); ++i) put_le(&h[kPackIndexHeaderFixed + 4 * i], std::uint32_t(cameras_[i]), 4);
  // CRC over the header without its own field (bytes 56..59) and the padding.
  std::uint32_t c = crc32(h.data(), 56);
  c = crc32(h.data() + kPackIndexHeaderFixed, 4 * cameras_.size(), c);
  put_le(&h[56], c, 4);
  // Header after the init it names: an index is never ahead of its pack.
  write_all(index_.get(), h.data(), h.size(), 0, index_path_);
  index_end_ = h.size();
}

PackWriter::~PackWriter() = default;

int PackWriter::slot(int camera) const {
  const auto it = std::lower_bound(cameras_.begin(), cameras_.end(), camera);
  return it != cameras_.end() && *it == camera ? int(it - cameras_.begin()) : -1;
}

std::uint64_t PackWriter::append(const std::uint8_t* data, std::size_t size) {
  std::uint64_t at;
  {
    std::lock_guard lock(mutex_);
    at = end_;
    end_ += size;
  }
  write_all(pack_.get(), data, size, at, pack_path_);
  return at;
}

std::uint64_t PackWriter::bytes() const { return end_; }

void PackWriter::write_round(const std::vector<PackRecord>& records) {
  const std::size_t n = cameras_.size() * std::size_t(tasks_);
  if (records.size() != n) throw Error(index_path_.string() + ": a round needs " + std::to_string(n) + " records");
  std::vector<std::uint8_t> buf(n * kPackRecordBytes);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t stream = std::uint32_t(cameras_[i / std::size_t(tasks_)]) * std::uint32_t(tasks_) +
                                 std::uint32_t(i % std::size_t(tasks_));
    encode_record(&buf[i * kPackRecordBytes], records[i], stream);
  }
  write_all(index_.get(), buf.data(), buf.size(), index_end_, index_path_);
  index_end_ += buf.size();
}

// --- reader ---

int PackIndexInfo::slot(int camera) const {
  const auto it = std::lower_bound(cameras.begin(), cameras.end(), camera);
  return it != cameras.end() && *it == camera ? int(it - cameras.begin()) : -1;
}

PackIndexInfo read_pack_index(int packs_dir_fd, const fs::path& packs_dir, int segment, int rank, int tasks,
                              int cameras_total) {
  PackIndexInfo info;
  info.segment = segment;
  info.rank = rank;
  info.tasks = tasks;
  const std::string index_name = pack_index_name(segment, rank), pack_name = pack_file_name(segment, rank);
  info.index = packs_dir / index_name;
  info.pack = packs_dir / pack_name;
  const std::string where = info.index.string();
  constexpr std::uint64_t kMaxIndex = std::uint64_t(1) << 40;
  FileHandle idx = open_regular_file(packs_dir_fd, index_name, kMaxIndex, "pack index", packs_dir);
  FileHandle pack = open_regular_file(packs_dir_fd, pack_name, kMaxIndex * 64, "pack", packs_dir);
  struct stat st{};
  if (::fstat(idx.get(), &st) != 0) throw FileError(where, std::string("cannot stat: ") + std::strerror(errno));
  const std::uint64_t index_size = std::uint64_t(st.st_size);
  if (::fstat(pack.get(), &st) != 0) throw FileError(info.pack.string(), std::string("cannot stat: ") + std::strerror(errno));
  info.pack_size = std::uint64_t(st.st_size);
  std::uint8_t h[kPackIndexHeaderFixed];
  if (index_size < kPackIndexHeaderFixed || !read_all(idx.get(), h, sizeof h, 0))
    throw FileError(where, "pack index is truncated (" + std::to_string(index_size) + " bytes; its header has " +
                               std::to_string(kPackIndexHeaderFixed) + ")");
  if (std::memcmp(h, kPackIndexMagic, 8) != 0) throw FileError(where, "not a pack index (magic is not PNPTPIDX)");
  const auto version = get_le(h + 8, 4);
  if (version != kPackIndexVersion)
    throw FileError(where, "pack index version " + std::to_string(version) + " is not supported (this build reads " +
                               std::to_string(kPackIndexVersion) + ")");
  const std::uint64_t ncam = get_le(h + 24, 4);
  info.header_bytes = get_le(h + 12, 4);
  if (get_le(h + 16, 4) != std::uint64_t(segment) || get_le(h + 20, 4) != std::uint64_t(rank))
    throw FileError(where, "pack index says segment " + std::to_string(get_le(h + 16, 4)) + ", rank " +
                               std::to_string(get_le(h + 20, 4)) + "; its name says segment " + std::to_string(segment) +
                               ", rank " + std::to_string(rank));
  if (get_le(h + 28, 4) != std::uint64_t(tasks))
    throw FileError(where, "pack index has " + std::to_string(get_le(h + 28, 4)) + " tasks per camera; the manifest " +
                               std::to_string(tasks));
  if (ncam > std::uint64_t(cameras_total))
    throw FileError(where, "pack index lists " + std::to_string(ncam) + " cameras; the database has " +
                               std::to_string(cameras_total));
  if (info.header_bytes != header_bytes_for(std::size_t(ncam)) || info.header_bytes > index_size)
    throw FileError(where, "pack index header size " + std::to_string(info.header_bytes) + " does not fit " +
                               std::to_string(ncam) + " cameras in a file of " + std::to_string(index_size) + " bytes");
  std::vector<std::uint8_t> list(4 * std::size_t(ncam));
  if (!read_all(idx.get(), list.data(), list.size(), kPackIndexHeaderFixed))
    throw FileError(where, "cannot read the pack index's camera list");
  std::uint32_t c = crc32(h, 56);
  c = crc32(list.data(), list.size(), c);
  if (c != get_le(h + 56, 4)) throw FileError(where, "pack index header is damaged (its CRC-32 does not match)");
  info.cameras.resize(std::size_t(ncam));
  for (std::size_t i = 0; i < ncam; ++i) {
    const std::uint64_t cam = get_le(&list[4 * i], 4);
    if (cam >= std::uint64_t(cameras_total) || (i > 0 && int(cam) <= info.cameras[i - 1]))
      throw FileError(where, "pack index camera list entry " + std::to_string(i) + " is " + std::to_string(cam) +
                                 " (expected ascending cameras below " + std::to_string(cameras_total) + ")");
    info.cameras[i] = int(cam);
  }
  info.first_frame = std::uint32_t(get_le(h + 32, 4));
  info.timescale = std::uint32_t(get_le(h + 36, 4));
  info.frame_ticks = std::uint32_t(get_le(h + 40, 4));
  info.init_size = get_le(h + 44, 4);
  info.init_offset = get_le(h + 48, 8);
  if (info.timescale == 0 || info.frame_ticks == 0)
    throw FileError(where, "pack index has time scale " + std::to_string(info.timescale) + " and frame duration " +
                               std::to_string(info.frame_ticks) + " (both must be > 0)");
  if (info.init_size < 8 || info.init_offset > info.pack_size || info.init_size > info.pack_size - info.init_offset)
    throw FileError(where, "pack index names an init segment at bytes " + std::to_string(info.init_offset) + "+" +
                               std::to_string(info.init_size) + ", outside its pack (" + std::to_string(info.pack_size) +
                               " bytes)");
  const std::uint64_t rb = info.round_bytes();
  // A round cut short (the writer was killed while writing it) is ignored.
  info.rounds = rb == 0 ? 0 : (index_size - info.header_bytes) / rb;
  return info;
}

std::vector<PackRecord> read_stream_records(int index_fd, const PackIndexInfo& info, int camera, int task) {
  std::vector<PackRecord> out;
  const int slot = info.slot(camera);
  if (slot < 0) return out;
  const std::uint32_t stream = std::uint32_t(camera) * std::uint32_t(info.tasks) + std::uint32_t(task);
  for (std::uint64_t k = 0; k < info.rounds; ++k) {
    std::uint8_t b[kPackRecordBytes];
    if (!read_all(index_fd, b, sizeof b, info.record_offset(k, slot, task)))
      throw FileError(info.index.string(), "cannot read round " + std::to_string(k) + " (the index shrank)");
    PackRecord r{get_le(b, 8), std::uint32_t(get_le(b + 8, 4)), std::uint32_t(get_le(b + 12, 4)),
                 std::uint32_t(get_le(b + 16, 4))};
    if (pack_record_check(r, stream) != get_le(b + 20, 4))
      throw FileError(info.index.string(), "record of camera " + std::to_string(camera) + ", task " + std::to_string(task) +
                                               " in round " + std::to_string(k) + " is damaged (its check word does not match)");
    if (r.frames == 0) continue;
    // Bytes the pack does not hold (yet): the tail of a killed run. Nothing after it is used.
    if (r.offset > info.pack_size || r.size > info.pack_size - r.offset) break;
    out.push_back(r);
  }
  return out;
}

int PackedStream::frames() const {
  int n = 0;
  for (const Piece& p : pieces) n += p.frames;
  return n;
}

std::vector<video::FilePiece> PackedStream::file_pieces() const {
  std::vector<video::FilePiece> out;
  out.reserve(pieces.size());
  for (const Piece& p : pieces) out.push_back({p.file.string(), p.offset, p.size});
  return out;
}

PackedStream assemble_stream(const std::vector<std::pair<const PackIndexInfo*, std::vector<PackRecord>>>& segments,
                             int camera, int task) {
  PackedStream s;
  const PackIndexInfo* init_from = nullptr;
  struct Chosen {
    const PackIndexInfo* info;
    PackRecord r;
  };
  std::vector<Chosen> chosen;
  int end = 0;
  for (const auto& [info, records] : segments) {
    if (!init_from) init_from = info;
    for (const PackRecord& r : records) {
      if (r.first_frame > std::uint32_t(end)) break;  // a gap: the frames between are lost
      if (r.frames > std::uint32_t(INT32_MAX) - r.first_frame)
        throw FileError(info->index.string(), "record of camera " + std::to_string(camera) + ", task " + std::to_string(task) +
                                                  " claims frames " + std::to_string(r.first_frame) + "+" +
                                                  std::to_string(r.frames));
      while (!chosen.empty() && chosen.back().r.first_frame >= r.first_frame) chosen.pop_back();
      end = chosen.empty() ? 0 : int(chosen.back().r.first_frame + chosen.back().r.frames);
      if (r.first_frame != std::uint32_t(end)) break;  // starts inside a fragment chosen before: unusable
      // Ranges inside the pack, not over its init segment, after the previous fragment of this pack.
      if (r.offset < info->init_offset + info->init_size || r.size < 16)
        throw FileError(info->pack.string(), "index record of camera " + std::to_string(camera) + ", task " +
                                                 std::to_string(task) + " names bytes " + std::to_string(r.offset) + "+" +
                                                 std::to_string(r.size) + ", which overlap the init segment or are too short");
      for (const Chosen& c : chosen)
        if (c.info == info && r.offset < c.r.offset + c.r.size && c.r.offset < r.offset + r.size)
          throw FileError(info->pack.string(), "index records of camera " + std::to_string(camera) + ", task " +
                                                   std::to_string(task) + " overlap (bytes " + std::to_string(c.r.offset) +
                                                   "+" + std::to_string(c.r.size) + " and " + std::to_string(r.offset) + "+" +
                                                   std::to_string(r.size) + ")");
      chosen.push_back({info, r});
      end = int(r.first_frame + r.frames);
    }
  }
  if (!init_from) return s;
  s.pieces.push_back({init_from->pack, init_from->init_offset, init_from->init_size, 0, 0});
  for (const Chosen& c : chosen)
    s.pieces.push_back({c.info->pack, c.r.offset, c.r.size, int(c.r.first_frame), int(c.r.frames)});
  return s;
}

}  // namespace panoptes::store
