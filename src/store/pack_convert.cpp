#include "store/pack_convert.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.hpp"
#include "store/camera_table.hpp"
#include "store/database.hpp"
#include "store/pack.hpp"
#include "store/safe_file.hpp"
#include "video/fmp4_fragment.hpp"

namespace panoptes::store {

namespace fs = std::filesystem;

namespace {

// The source database, which must be finished (no live writer), and an empty or new target.
Database open_source(const fs::path& in, const fs::path& out) {
  Database db = Database::open(in);
  if (db.status() == Status::running)
    throw FileError(in.string(), "a writer is still running; convert it when the run has ended");
  std::error_code ec;
  if (fs::exists(out, ec) && (!fs::is_directory(out, ec) || !fs::is_empty(out, ec)))
    throw FileError(out.string(), "exists and is not an empty directory; refusing to write into it");
  if (fs::equivalent(in, out, ec)) throw FileError(out.string(), "is the source database itself");
  fs::create_directories(out, ec);
  if (ec) throw FileError(out.string(), "cannot create the directory: " + ec.message());
  return db;
}

void finish(const fs::path& out, Manifest m) {
  const CameraTableRef table = write_camera_table(out, m);
  write_manifest_atomic(out / kManifestFileName, m, table);
}

std::vector<std::uint8_t> read_range(int fd, std::uint64_t offset, std::uint64_t size, const fs::path& path) {
  std::vector<std::uint8_t> b(size);
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pread(fd, b.data() + done, size - done, off_t(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw FileError(path.string(), "cannot read bytes " + std::to_string(offset) + "+" + std::to_string(size));
    done += std::size_t(n);
  }
  return b;
}

}  // namespace

void pack_database(const fs::path& in, const fs::path& out, const ConvertProgress& progress) {
  const Database db = open_source(in, out);
  if (db.packed()) throw Error(in.string() + ": is already packed");
  const Manifest& src = db.manifest();
  const int cameras = db.camera_count(), tasks = db.task_count(), frames = db.frame_count();
  const std::int64_t total = db.stream_count();
  std::vector<int> all(static_cast<std::size_t>(cameras));
  for (int c = 0; c < cameras; ++c) all[std::size_t(c)] = c;
  FileHandle dir = open_directory(out);
  FileHandle packs = open_subdirectory(dir.get(), kPackDirectory, true, out);
  std::unique_ptr<PackWriter> pack;
  std::vector<std::uint8_t> header;  // the stream header every stream must share
  std::uint32_t ticks = 0;
  std::vector<PackRecord> records(static_cast<std::size_t>(total));
  std::vector<std::uint8_t> samples, fragment;
  for (std::int64_t i = 0; i < total; ++i) {
    const int c = int(i / tasks), t = int(i % tasks);
    auto reader = db.stream(c, t);
    if (!pack) {
      header = reader->stream_header();
      std::uint32_t timescale = 0;
      const auto init = video::make_init_segment(header, reader->coded_width(), reader->coded_height(), src.video,
                                                 &timescale, &ticks);
      pack = std::make_unique<PackWriter>(packs.get(), out / kPackDirectory, 0, 0, all, tasks, 0, init, timescale, ticks);
    } else if (reader->stream_header() != header) {
      throw Error(reader->path() + ": its stream header (SPS/PPS) differs from the first stream's; one pack's init "
                                   "segment cannot serve both (re-encode, or keep the files layout)");
    }
    if (!reader->in_decode_order())
      throw Error(reader->path() + ": frames are not stored in presentation order; cannot pack it");
    // The checks a reader applies to every frame, without decoding: a damaged frame is not carried over.
    const std::vector<int> bad = reader->check_frames();
    if (!bad.empty() && bad.front() < frames)
      throw Error(reader->path() + ": frame " + std::to_string(bad.front()) + " is damaged; not packed");
    samples.clear();
    std::vector<video::FragmentSample> sizes;
    std::vector<std::uint8_t> packet;
    for (int f = 0; f < frames; ++f) {
      reader->read_packet(f, packet);
      samples.insert(samples.end(), packet.begin(), packet.end());
      sizes.push_back({std::uint32_t(packet.size()), reader->is_keyframe(f)});
    }
    if (frames > 0) {
      fragment.clear();
      video::append_fragment(fragment, 1, 0, ticks, sizes, samples.data(), samples.size());
      const std::uint64_t at = pack->append(fragment.data(), fragment.size());
      records[std::size_t(i)] = {at, std::uint32_t(fragment.size()), 0, std::uint32_t(frames)};
    }
    if (progress && (i % 256 == 0)) progress(i, total);
  }
  if (pack && frames > 0) pack->write_round(records);
  Manifest m = src;
  m.status = db.stored_status() == Status::running ? Status::interrupted : db.stored_status();
  m.layout = Layout::packed;
  m.packs = {{0, 0, 1}};
  finish(out, m);
  if (progress) progress(total, total);
}

void unpack_database(const fs::path& in, const fs::path& out, const ConvertProgress& progress) {
  const Database db = open_source(in, out);
  if (!db.packed()) throw Error(in.string() + ": is not packed (its movies are files already)");
  const Manifest& src = db.manifest();
  const int tasks = db.task_count(), frames = db.frame_count();
  const std::int64_t total = db.stream_count();
  FileHandle dir = open_directory(out);
  std::vector<std::pair<fs::path, FileHandle>> open_packs;  // a few: one per rank and segment
  auto pack_fd = [&](const fs::path& file) {
    for (const auto& [p, h] : open_packs)
      if (p == file) return h.get();
    FileHandle d = open_directory(file.parent_path());
    open_packs.emplace_back(file, open_regular_file(d.get(), file.filename().string(), std::uint64_t(1) << 46, "pack",
                                                    file.parent_path()));
    return open_packs.back().second.get();
  };
  for (std::int64_t i = 0; i < total; ++i) {
    const int c = int(i / tasks), t = int(i % tasks);
    db.stream(c, t);  // every check a reader makes, before the bytes are copied
    const PackedStream ps = db.packed_stream(c, t);
    const std::string relative = src.stream_relative_path(c, t);
    const auto slash = relative.rfind('/');
    FileHandle sub = open_subdirectory(dir.get(), slash == std::string::npos ? "" : relative.substr(0, slash), true, out);
    FileHandle file = open_for_writing(sub.get(), relative.substr(slash == std::string::npos ? 0 : slash + 1), true,
                                       "movie", out);
    std::uint64_t at = 0;
    for (const auto& piece : ps.pieces) {
      if (piece.frames > 0 && piece.first_frame >= frames) break;  // beyond the checkpoint
      const std::vector<std::uint8_t> bytes = read_range(pack_fd(piece.file), piece.offset, piece.size, piece.file);
      std::size_t done = 0;
      while (done < bytes.size()) {
        const ssize_t n = ::pwrite(file.get(), bytes.data() + done, bytes.size() - done, off_t(at + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw FileError((out / relative).string(), std::string("cannot write: ") + std::strerror(errno));
        done += std::size_t(n);
      }
      at += bytes.size();
    }
    if (progress && (i % 256 == 0)) progress(i, total);
  }
  Manifest m = src;
  m.status = db.stored_status() == Status::running ? Status::interrupted : db.stored_status();
  m.layout = Layout::files;
  m.packs.clear();
  finish(out, m);
  if (progress) progress(total, total);
}

}  // namespace panoptes::store
