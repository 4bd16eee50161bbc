// The movie database on disk, writing: DatabaseWriter (create, append, checkpoint, finalize, resume)
// and the writer's liveness lock (database.cpp reads: Database).
// Sections (each marked "// --- name ---" below):
//   helpers     host name, locks, the database id, frame checks on disk, removing an overwritten database
//   writer      DatabaseWriter::Impl and create, append, close, times, notes, checkpoints, finalize
//   resume      DatabaseWriter::resume: continuing a database after a restart
//   liveness    writer_is_alive: the lock a live writer holds
#include "store/database.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <ctime>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <mutex>
#include <random>
#include <thread>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/parallel_for.hpp"
#include "core/utc_time.hpp"
#include "store/atomic_file.hpp"
#include "store/bounded_json.hpp"
#include "store/camera_table.hpp"
#include "store/manifest_diff.hpp"
#include "store/owned_files.hpp"
#include "store/safe_file.hpp"
#include "store/pack.hpp"
#include "video/fmp4_fragment.hpp"
#include "video/intra_packet_encoder.hpp"
#include "video/movie_reader.hpp"
#include "video/movie_writer.hpp"

namespace panoptes::store {

namespace fs = std::filesystem;

// --- helpers ---
namespace {

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

bool lock_unsupported(int err) { return err == ENOLCK || err == ENOSYS || err == EOPNOTSUPP || err == EINVAL; }

// 64 random bits as 16 lowercase hex digits: the database's identity in every frame it writes.
std::string random_database_id() {
  std::random_device rd;
  const std::uint64_t v = (std::uint64_t(rd()) << 32) ^ rd();
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The frame checks recorded by the manifest the root writer wrote in dir (non-root ranks stamp their
// movies with the same identity). Empty if it records none or cannot be read.
FrameCheckRecord frame_checks_on_disk(int dir_fd, const fs::path& dir) {
  FrameCheckRecord record;
  try {
    const nlohmann::json j = parse_bounded_json(
        read_regular_file(dir_fd, kManifestFileName, kMaxManifestBytes, "manifest", dir),
        (dir / kManifestFileName).string(), {}, "manifest");
    const auto& fc = j.at("frame_checks");
    record.scheme = fc.at("scheme").get<std::string>();
    record.database_id = fc.at("database_id").get<std::string>();
  } catch (const std::exception&) {
    return {};
  }
  return record;
}

// The layout and last pack segment the root writer recorded in dir (non-root ranks write their packs
// into that segment). Files layout if it cannot be read.
std::pair<Layout, PackSegment> layout_on_disk(int dir_fd, const fs::path& dir) {
  try {
    const Manifest m = read_manifest(dir / kManifestFileName);
    if (m.layout == Layout::packed && !m.packs.empty()) return {Layout::packed, m.packs.back()};
  } catch (const std::exception&) {
  }
  (void)dir_fd;
  return {Layout::files, {}};
}

// The overwrite of an old database: removes the movies its manifest lists (and the directories
// left empty); reports its camera table for removal after the new one is written.
void remove_old_database_files(int dir_fd, const fs::path& dir, std::string* old_table) {
  const OldDatabaseFiles old = describe_old_database(dir_fd, dir);
  remove_owned_files(dir_fd, find_listed_movies(dir_fd, old.movie_pattern, old.cameras, old.tasks), dir);
  if (!old.packs.empty()) remove_owned_files(dir_fd, old.packs, dir);
  *old_table = old.camera_table;
}

}  // namespace

// --- writer ---

LayoutChoice parse_layout_choice(std::string_view text) {
  if (text == "auto") return LayoutChoice::automatic;
  if (text == "files") return LayoutChoice::files;
  if (text == "packed") return LayoutChoice::packed;
  throw Error("layout \"" + std::string(text.substr(0, 64)) + "\" is not one of auto, files, packed");
}

struct DatabaseWriter::Impl {
  struct Stream {
    std::unique_ptr<video::MovieWriter> writer;  // files layout
    int frames = 0;
    bool closed = false;
    // Packed layout: samples appended since the last fragment (MP4 form, back to back) and their
    // sizes; frames before `flushed` are in the pack. An idle stream holds no heap memory.
    int flushed = 0;
    std::vector<std::uint8_t> pending;
    std::vector<std::uint32_t> pending_sizes;
    PackRecord written;  // a fragment close_stream() wrote that the next index round must name
  };

  fs::path dir;
  Manifest manifest;
  WriterOptions options;
  std::vector<int> slot_of_camera;  // camera -> index among owned cameras, -1 if not owned
  int owned = 0;
  std::vector<Stream> streams;      // owned × tasks, row-major by owned camera
  std::mutex mutex;                 // guards manifest.image padding updates and directory creation
  int lock_fd = -1;
  FileHandle dir_fd;  // the database directory: every name inside is opened relative to it
  bool finalized = false;
  CameraTableRef table;  // the camera table written by create() (manifest writer only)
  // Packed layout: one encoder shared by every stream, this writer's pack, and the slot of each owned
  // camera in it (the pack lists cameras ascending).
  bool packed = false;
  bool pack_failed = false;  // a pack or index write failed: nothing more is written
  std::unique_ptr<video::IntraPacketEncoder> encoder;
  std::unique_ptr<PackWriter> pack;
  std::vector<int> camera_of_slot;
  std::uint32_t frame_ticks = 0;

  // Opens this writer's pack of `segment` starting at `first_frame` (packs/ is created if missing).
  void open_pack(int segment, int first_frame) {
    packed = true;
    const auto& im = manifest.image;
    encoder = std::make_unique<video::IntraPacketEncoder>(im.width, im.height, manifest.video,
                                                          (dir / kPackDirectory).string());
    manifest.image.padded_width = encoder->padded_width();
    manifest.image.padded_height = encoder->padded_height();
    std::uint32_t timescale = 0;
    const std::vector<std::uint8_t> init = video::make_init_segment(
        encoder->header(), encoder->padded_width(), encoder->padded_height(), manifest.video, &timescale, &frame_ticks);
    FileHandle packs_dir = open_subdirectory(dir_fd.get(), kPackDirectory, true, dir);
    pack = std::make_unique<PackWriter>(packs_dir.get(), dir / kPackDirectory, segment, options.rank, camera_of_slot,
                                        manifest.task_count(), first_frame, init, timescale, frame_ticks);
  }

  // Appends the pending samples of s as one fragment to `out` and returns its record (offset relative
  // to `out`'s start); the samples are freed.
  PackRecord make_fragment(Stream& s, std::vector<std::uint8_t>& out) {
    PackRecord r;
    r.first_frame = std::uint32_t(s.flushed);
    r.frames = std::uint32_t(s.pending_sizes.size());
    r.offset = out.size();
    std::vector<video::FragmentSample> samples;
    samples.reserve(s.pending_sizes.size());
    for (std::uint32_t n : s.pending_sizes) samples.push_back({n, true});
    video::append_fragment(out, std::uint32_t(s.flushed) + 1, std::uint64_t(s.flushed) * frame_ticks, frame_ticks,
                           samples, s.pending.data(), s.pending.size());
    r.size = std::uint32_t(out.size() - r.offset);
    s.flushed += int(r.frames);
    std::vector<std::uint8_t>().swap(s.pending);
    std::vector<std::uint32_t>().swap(s.pending_sizes);
    return r;
  }

  // Packed: writes every stream's pending frames as one fragment each (batched into large writes),
  // then the index round naming them. After it returns, the frames are in the pack and indexed.
  void flush_packed() {
    if (!pack) return;
    if (pack_failed)
      throw FileError(pack->pack_path().string(), "an earlier write failed; the database ends at its last checkpoint");
    try {
      write_packed_round();
    } catch (...) {
      pack_failed = true;  // frames of this round are lost: later rounds would leave a gap
      throw;
    }
  }

  void write_packed_round() {
    const int tasks = manifest.task_count();
    std::vector<PackRecord> records(streams.size());
    std::vector<std::uint8_t> batch;
    std::vector<std::size_t> in_batch;  // records whose offset is relative to the batch
    auto write_batch = [&] {
      if (batch.empty()) return;
      const std::uint64_t base = pack->append(batch.data(), batch.size());
      for (std::size_t i : in_batch) records[i].offset += base;
      batch.clear();
      in_batch.clear();
    };
    constexpr std::size_t kBatch = std::size_t(8) << 20;
    for (std::size_t i = 0; i < streams.size(); ++i) {
      Stream& s = streams[i];
      const int camera = camera_of_slot[i / std::size_t(tasks)];
      const std::size_t at = std::size_t(pack->slot(camera)) * std::size_t(tasks) + i % std::size_t(tasks);
      if (!s.pending_sizes.empty()) {
        records[at] = make_fragment(s, batch);
        in_batch.push_back(at);
        if (batch.size() >= kBatch) write_batch();
      } else if (s.written.frames > 0) {
        records[at] = s.written;
        s.written = {};
      }
    }
    write_batch();
    // A round that names nothing is not written (a flush with no new frame costs no index space).
    if (std::none_of(records.begin(), records.end(), [](const PackRecord& r) { return r.frames > 0; })) return;
    // Only now the records: an index never names bytes that are not yet in the pack.
    pack->write_round(records);
  }

  Stream& stream(int camera, int task) {
    if (finalized) throw Error(dir.string() + ": database already finalized; cannot append");
    if (camera < 0 || camera >= manifest.camera_count())
      throw Error(dir.string() + ": camera " + std::to_string(camera) + " out of range (database has " +
                  std::to_string(manifest.camera_count()) + " cameras)");
    if (task < 0 || task >= manifest.task_count())
      throw Error(dir.string() + ": task " + std::to_string(task) + " out of range (database has " +
                  std::to_string(manifest.task_count()) + " tasks)");
    const int slot = slot_of_camera[std::size_t(camera)];
    if (slot < 0) throw Error(dir.string() + ": camera " + std::to_string(camera) + " is not owned by this writer");
    return streams[std::size_t(slot) * std::size_t(manifest.task_count()) + std::size_t(task)];
  }

  int complete_frames() const {
    if (streams.empty()) return 0;
    int m = streams.front().frames;
    for (const auto& s : streams) m = std::min(m, s.frames);
    return m;
  }

  // Flushes every open movie in parallel; the first failure is rethrown naming its stream.
  void flush_all() {
    if (packed) {
      flush_packed();
      return;
    }
    const int threads = int(std::max(1u, std::thread::hardware_concurrency()));
    parallel_for(std::int64_t(streams.size()), streams.size() > 16 ? threads : 1, [&](std::int64_t i) {
      if (streams[std::size_t(i)].writer) streams[std::size_t(i)].writer->flush();
    });
  }

  // Rewrites panoptes.json only: the camera table, written once by create(), cannot change during a
  // run (a checkpoint of 10^5 cameras would otherwise rewrite megabytes every snapshot). No copy of
  // the manifest either: the fields are restored if the write fails.
  void write_manifest(Status status, int frames_written) {
    const Status old_status = manifest.status;
    const int old_frames = manifest.frames_written;
    manifest.status = status;
    manifest.frames_written = frames_written;
    try {
      write_manifest_atomic(dir / kManifestFileName, manifest, table);
    } catch (...) {
      manifest.status = old_status;
      manifest.frames_written = old_frames;
      throw;
    }
  }

  void release_lock() {
    if (lock_fd >= 0) {
      ::unlinkat(dir_fd.get(), kLockFileName, 0);
      ::close(lock_fd);  // drops the flock
      lock_fd = -1;
    }
  }

  void take_lock() {
    const fs::path path = dir / kLockFileName;
    // Never through a link (`ln -s ~/f DB/.panoptes.lock` must not truncate ~/f), never a FIFO or
    // device; the file is truncated only once we hold the lock.
    lock_fd = open_for_writing(dir_fd.get(), kLockFileName, false, "writer lock", dir).release();
    if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      if (err == EWOULDBLOCK) {
        ::close(lock_fd);
        lock_fd = -1;
        throw FileError(dir.string(), "another process is writing this database right now (lock " + path.string() + ")");
      }
      if (!lock_unsupported(err)) {
        ::close(lock_fd);
        lock_fd = -1;
        throw FileError(path.string(), std::string("cannot lock: ") + std::strerror(err));
      }
      // File systems without flock: readers fall back to the pid check on the same host.
      log::warn(dir.string() + ": file locks unsupported here; liveness falls back to the writer's pid");
    }
    const std::string who = std::to_string(::getpid()) + " " + host_name() + "\n";
    if (::ftruncate(lock_fd, 0) != 0 || ::pwrite(lock_fd, who.data(), who.size(), 0) != ssize_t(who.size()))
      throw FileError(path.string(), std::string("cannot write the writer lock: ") + std::strerror(errno));
  }
};

DatabaseWriter::DatabaseWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DatabaseWriter::DatabaseWriter(DatabaseWriter&&) noexcept = default;
DatabaseWriter& DatabaseWriter::operator=(DatabaseWriter&& other) noexcept {
  if (this != &other) {
    DatabaseWriter old(std::move(*this));  // an unfinalized target is marked interrupted, as on destruction
    impl_ = std::move(other.impl_);
  }
  return *this;
}

DatabaseWriter DatabaseWriter::create(const fs::path& dir, Manifest manifest, bool overwrite) {
  WriterOptions options;
  options.overwrite = overwrite;
  return create(dir, std::move(manifest), options);
}

DatabaseWriter DatabaseWriter::create(const fs::path& dir, Manifest manifest, const WriterOptions& options) {
  if (manifest.image.padded_width == 0 && manifest.image.padded_height == 0) {
    // H.264 4:2:0 needs even sizes; MovieWriter pads odd ones by repeating the edge.
    manifest.image.padded_width = (manifest.image.width + 1) & ~1;
    manifest.image.padded_height = (manifest.image.height + 1) & ~1;
  }
  // Provenance every writer would otherwise fill in by hand.
  if (manifest.provenance.created.empty()) manifest.provenance.created = utc_now_iso8601();
  if (manifest.provenance.host.empty()) manifest.provenance.host = host_name();
  manifest.status = Status::running;
  manifest.frames_written = 0;
  manifest.schema_version = kSchemaVersion;
  // Every frame this writer encodes carries the movie's identity (kept when the caller passes a
  // manifest that already has one, e.g. an older run's).
  if (!manifest.frame_checks.recorded()) manifest.frame_checks = {kFrameCheckScheme, random_database_id()};
  try {
    manifest.validate();
  } catch (const Error& e) {
    throw Error(dir.string() + ": cannot create the database: " + e.what());
  }

  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->options = options;
  impl->slot_of_camera.assign(std::size_t(manifest.camera_count()), -1);
  if (options.owned_cameras.empty()) {
    for (int c = 0; c < manifest.camera_count(); ++c) impl->slot_of_camera[std::size_t(c)] = impl->owned++;
  } else {
    for (int c : options.owned_cameras) {
      if (c < 0 || c >= manifest.camera_count())
        throw Error(dir.string() + ": owned camera " + std::to_string(c) + " out of range (database has " +
                    std::to_string(manifest.camera_count()) + " cameras)");
      if (impl->slot_of_camera[std::size_t(c)] < 0) impl->slot_of_camera[std::size_t(c)] = impl->owned++;
    }
  }
  impl->streams.resize(std::size_t(impl->owned) * std::size_t(manifest.task_count()));
  impl->camera_of_slot.resize(std::size_t(impl->owned));
  for (int c = 0; c < manifest.camera_count(); ++c)
    if (impl->slot_of_camera[std::size_t(c)] >= 0) impl->camera_of_slot[std::size_t(impl->slot_of_camera[std::size_t(c)])] = c;
  const bool want_packed = options.layout == LayoutChoice::packed ||
                           (options.layout == LayoutChoice::automatic && manifest.video.gop == 1 &&
                            manifest.stream_count() >= kPackedAutoStreams);
  if (options.rank < 0 || options.ranks < 1 || options.rank >= options.ranks)
    throw Error(dir.string() + ": writer rank " + std::to_string(options.rank) + " of " + std::to_string(options.ranks) +
                " ranks; expected 0 <= rank < ranks");
  if (options.writes_manifest) {
    manifest.layout = want_packed ? Layout::packed : Layout::files;
    manifest.packs.clear();
    if (want_packed) manifest.packs.push_back({0, 0, options.ranks});
  }
  impl->manifest = std::move(manifest);

  if (!options.writes_manifest) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw FileError(dir.string(), "database directory does not exist (create it on the root writer first)");
    impl->dir_fd = open_directory(dir);
    impl->manifest.frame_checks = frame_checks_on_disk(impl->dir_fd.get(), dir);
    const auto [layout, segment] = layout_on_disk(impl->dir_fd.get(), dir);
    impl->manifest.layout = layout;
    if (layout == Layout::packed) impl->open_pack(segment.segment, segment.first_frame);
    return DatabaseWriter(std::move(impl));
  }

  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) throw FileError(dir.string(), "exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw FileError(dir.string(), "cannot create the database directory: " + ec.message());
  impl->dir_fd = open_directory(dir);
  impl->take_lock();  // before looking at an old database, so two creators cannot both proceed

  std::string old_table;  // the old camera table, removed once the new one is written
  struct stat manifest_stat{};
  if (::fstatat(impl->dir_fd.get(), kManifestFileName, &manifest_stat, AT_SYMLINK_NOFOLLOW) == 0) {
    if (!options.overwrite) {
      impl->release_lock();
      throw FileError(dir.string(), "already holds a Panoptes database (panoptes.json); refusing to overwrite it (" +
                                        (options.overwrite_option.empty() ? std::string("WriterOptions::overwrite")
                                                                          : options.overwrite_option) +
                                        " replaces it)");
    }
    // Only what the old manifest lists goes (owned_files.hpp): its movies, the directories that
    // become empty, its camera table; a user's file beside them, or a link's target, stays.
    try {
      remove_old_database_files(impl->dir_fd.get(), dir, &old_table);
    } catch (...) {
      impl->release_lock();
      throw;
    }
    ::unlinkat(impl->dir_fd.get(), kManifestFileName, 0);  // a link is removed, never followed
  }
  remove_stale_temp_files(impl->dir_fd.get());  // a killed writer's half-written manifest or table
  try {
    // The pack first: its encoder settles the padded size the manifest records.
    if (impl->manifest.layout == Layout::packed) impl->open_pack(0, 0);
    impl->table = write_camera_table(dir, impl->manifest);
    impl->write_manifest(Status::running, 0);
  } catch (...) {
    impl->release_lock();
    throw;
  }
  if (!old_table.empty() && old_table != impl->table.file) ::unlinkat(impl->dir_fd.get(), old_table.c_str(), 0);
  return DatabaseWriter(std::move(impl));
}

DatabaseWriter::~DatabaseWriter() {
  if (!impl_ || impl_->finalized) return;
  if (impl_->options.writes_manifest) {
    try {
      int frames = impl_->manifest.frames_written;
      try {
        impl_->flush_all();
        frames = impl_->complete_frames();
      } catch (...) {
        // Keep the last checkpoint's count: not every movie is known to hold more.
      }
      impl_->write_manifest(Status::interrupted, frames);
    } catch (...) {
      // Best effort: the manifest on disk still says `running`, which readers report as interrupted.
    }
  }
  impl_->streams.clear();  // closes the movies
  impl_->release_lock();
}

void DatabaseWriter::append(int camera, int task, const Image& frame) {
  auto& s = impl_->stream(camera, task);
  if (s.closed)
    throw Error(impl_->dir.string() + ": stream camera " + std::to_string(camera) + ", task " + std::to_string(task) +
                " was closed; cannot append");
  const auto& im = impl_->manifest.image;
  if (frame.width != im.width || frame.height != im.height)
    throw Error(impl_->dir.string() + ": frame for camera " + std::to_string(camera) + ", task " + std::to_string(task) +
                " is " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                ", expected the database image size " + std::to_string(im.width) + "x" + std::to_string(im.height));
  if (frame.channels != 3 && frame.channels != 4)
    throw Error(impl_->dir.string() + ": frame has " + std::to_string(frame.channels) + " channels, expected 3 or 4");
  if (impl_->packed) {
    if (impl_->pack_failed)
      throw FileError(impl_->pack->pack_path().string(), "an earlier write failed; the database ends at its last checkpoint");
    std::optional<video::MovieIdentity> identity;
    if (impl_->manifest.frame_checks.recorded()) identity = movie_identity(impl_->manifest, camera, task);
    const std::size_t n = impl_->encoder->encode(frame, std::uint32_t(s.frames), identity,
                                                 impl_->manifest.frame_checks.binds_parameter_sets(), s.pending);
    s.pending_sizes.push_back(std::uint32_t(n));
    ++s.frames;
    return;
  }
  if (!s.writer) {
    const std::string relative = impl_->manifest.stream_relative_path(camera, task);
    const fs::path path = impl_->dir / relative;
    // Every directory and the movie are opened relative to the database directory without following
    // links: a planted `movies -> /elsewhere` is refused, not written through.
    const auto slash = relative.rfind('/');
    FileHandle movie_dir;
    {
      std::lock_guard lock(impl_->mutex);
      movie_dir = open_subdirectory(impl_->dir_fd.get(), slash == std::string::npos ? "" : relative.substr(0, slash),
                                    true, impl_->dir);
    }
    FileHandle file = open_for_writing(movie_dir.get(), relative.substr(slash == std::string::npos ? 0 : slash + 1),
                                       true, "movie", path.parent_path());
    std::optional<video::MovieIdentity> identity;
    if (impl_->manifest.frame_checks.recorded()) identity = movie_identity(impl_->manifest, camera, task);
    auto writer = std::make_unique<video::MovieWriter>(file.release(), path.string(), im.width, im.height,
                                                       impl_->manifest.video, identity,
                                                       impl_->manifest.frame_checks.binds_parameter_sets());
    if (writer->padded_width() != im.padded_width || writer->padded_height() != im.padded_height) {
      std::lock_guard lock(impl_->mutex);
      impl_->manifest.image.padded_width = writer->padded_width();
      impl_->manifest.image.padded_height = writer->padded_height();
    }
    s.writer = std::move(writer);
  }
  s.writer->append(frame);
  ++s.frames;
}

void DatabaseWriter::close_stream(int camera, int task) {
  auto& s = impl_->stream(camera, task);
  if (impl_->packed && !s.pending_sizes.empty()) {
    // Written now (memory stays bounded), named by the next index round.
    std::vector<std::uint8_t> bytes;
    PackRecord r = impl_->make_fragment(s, bytes);
    r.offset = impl_->pack->append(bytes.data(), bytes.size());
    s.written = r;
  }
  if (s.writer) {
    s.writer->close();
    s.writer.reset();
  }
  s.closed = true;
}

void DatabaseWriter::set_time(int frame, double time) {
  if (frame < 0) throw Error("set_time: negative frame " + std::to_string(frame));
  auto& times = impl_->manifest.times;
  if (std::size_t(frame) >= times.size()) {
    const std::size_t old = times.size();
    times.resize(std::size_t(frame) + 1);
    for (std::size_t i = old; i < times.size(); ++i) times[i] = double(i);  // unknown times default to the index
  }
  times[std::size_t(frame)] = time;
}

void DatabaseWriter::set_note(const std::string& key, const std::string& value) {
  impl_->manifest.provenance.extra[key] = value;
}

void DatabaseWriter::set_field_reference(int frame, int field, double reference) {
  auto& fields = impl_->manifest.fields;
  if (field < 0 || field >= int(fields.size()))
    throw Error("set_field_reference: field " + std::to_string(field) + " out of range (the manifest lists " +
                std::to_string(fields.size()) + " fields)");
  if (frame < 0) throw Error("set_field_reference: negative frame " + std::to_string(frame));
  if (!(std::isfinite(reference) && reference > 0))
    throw Error("set_field_reference: reference " + std::to_string(reference) + " of field " + fields[std::size_t(field)].name +
                "; expected a finite value > 0");
  auto& refs = fields[std::size_t(field)].references;
  // Frames not given (yet) take the next given value: references stay a dense per-frame list.
  if (std::size_t(frame) >= refs.size()) refs.resize(std::size_t(frame) + 1, reference);
  refs[std::size_t(frame)] = reference;
}

void DatabaseWriter::flush() { impl_->flush_all(); }

int DatabaseWriter::complete_frames() const { return impl_->complete_frames(); }

void DatabaseWriter::checkpoint() {
  impl_->flush_all();
  if (impl_->options.writes_manifest) impl_->write_manifest(Status::running, impl_->complete_frames());
}

void DatabaseWriter::checkpoint(int frames_written) {
  impl_->flush_all();
  if (impl_->options.writes_manifest) impl_->write_manifest(Status::running, frames_written);
}

void DatabaseWriter::finalize() { finalize(-1); }

void DatabaseWriter::finalize(int frames_written) {
  if (impl_->finalized) return;
  auto& streams = impl_->streams;
  if (impl_->packed) impl_->flush_packed();
  parallel_for(std::int64_t(streams.size()), streams.size() > 16 ? 0 : 1, [&](std::int64_t i) {
    if (streams[std::size_t(i)].writer) streams[std::size_t(i)].writer->close();
  });
  if (frames_written < 0) frames_written = impl_->complete_frames();
  if (impl_->options.writes_manifest) impl_->write_manifest(Status::complete, frames_written);
  impl_->finalized = true;
  streams.clear();
  impl_->release_lock();
}

const Manifest& DatabaseWriter::manifest() const { return impl_->manifest; }
const fs::path& DatabaseWriter::dir() const { return impl_->dir; }

// --- resume ---

DatabaseWriter DatabaseWriter::resume(const fs::path& dir, Manifest manifest, const WriterOptions& options, int frames) {
  std::error_code ec;
  if (options.writes_manifest && !fs::exists(dir / kManifestFileName, ec) && !fs::is_symlink(dir / kManifestFileName, ec)) {
    WriterOptions fresh = options;
    fresh.overwrite = false;
    return create(dir, std::move(manifest), fresh);  // nothing to resume: a new database
  }
  if (manifest.image.padded_width == 0 && manifest.image.padded_height == 0) {
    manifest.image.padded_width = (manifest.image.width + 1) & ~1;
    manifest.image.padded_height = (manifest.image.height + 1) & ~1;
  }
  manifest.status = Status::running;
  manifest.frames_written = 0;
  manifest.schema_version = kSchemaVersion;
  try {
    manifest.validate();
  } catch (const Error& e) {
    throw Error(dir.string() + ": cannot resume the database: " + e.what());
  }
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->options = options;
  impl->slot_of_camera.assign(std::size_t(manifest.camera_count()), -1);
  std::vector<int> wanted = options.owned_cameras, owned;  // owned: camera of each slot
  if (wanted.empty())
    for (int c = 0; c < manifest.camera_count(); ++c) wanted.push_back(c);
  for (int c : wanted) {
    if (c < 0 || c >= manifest.camera_count())
      throw Error(dir.string() + ": owned camera " + std::to_string(c) + " out of range (database has " +
                  std::to_string(manifest.camera_count()) + " cameras)");
    if (impl->slot_of_camera[std::size_t(c)] < 0) {
      impl->slot_of_camera[std::size_t(c)] = impl->owned++;
      owned.push_back(c);
    }
  }
  impl->streams.resize(std::size_t(impl->owned) * std::size_t(manifest.task_count()));
  impl->camera_of_slot = owned;
  impl->manifest = std::move(manifest);
  if (!fs::is_directory(dir, ec)) throw FileError(dir.string(), "database directory does not exist; nothing to resume");
  impl->dir_fd = open_directory(dir);
  // Frames appended after the seam carry the identity the copied ones do (frame checks): the root
  // writer takes it from the old manifest, the others from the manifest the root has rewritten.
  if (!options.writes_manifest) impl->manifest.frame_checks = frame_checks_on_disk(impl->dir_fd.get(), dir);
  std::string old_table;
  if (options.writes_manifest) {
    impl->take_lock();  // a live writer of this database refuses the resume here
    try {
      const Manifest old = read_manifest(dir / kManifestFileName);
      const std::string differs = resume_mismatch(old, impl->manifest);
      if (!differs.empty())
        throw FileError(dir.string(), "cannot resume this database: " + differs +
                                          "; a resumed run must use the configuration it was written with");
      frames = old.frames_written;
      Manifest& m = impl->manifest;
      m.frame_checks = old.frame_checks;  // an older database without them stays without
      m.times.assign(old.times.begin(), old.times.begin() + std::min<std::ptrdiff_t>(std::ptrdiff_t(old.times.size()), frames));
      m.provenance.created = old.provenance.created.empty() ? utc_now_iso8601() : old.provenance.created;
      if (m.provenance.host.empty()) m.provenance.host = old.provenance.host.empty() ? host_name() : old.provenance.host;
      const std::string before = old.provenance.extra.count("resumed") ? old.provenance.extra.at("resumed") + " " : "";
      m.provenance.extra["resumed"] = before + utc_now_iso8601() + "@" + std::to_string(frames);
      for (const auto& [key, value] : old.provenance.extra) m.provenance.extra.try_emplace(key, value);
      old_table = referenced_camera_table(dir / kManifestFileName);
      // A packed database stays packed: the continuation goes into a new segment of packs.
      m.layout = old.layout;
      m.packs = old.packs;
      if (old.layout == Layout::packed) m.packs.push_back({old.packs.back().segment + 1, frames, options.ranks});
    } catch (...) {
      impl->release_lock();
      throw;
    }
  }
  if (frames < 0) throw Error(dir.string() + ": resume: the frame count of the root writer is required here");
  // Continues one owned stream: its movie is rewritten with its first `frames` frames copied as they
  // are, into `<movie>.resume`, renamed over the movie once complete (a crash before leaves the old one).
  auto resume_stream = [](Impl& impl, int camera, int task, int frames, Impl::Stream& s) {
    s.frames = frames;
    if (frames == 0) return;  // the first append creates the movie afresh
    const Manifest& man = impl.manifest;
    const std::string relative = man.stream_relative_path(camera, task);
    const fs::path path = impl.dir / relative;
    const auto slash = relative.rfind('/');
    const std::string leaf = relative.substr(slash == std::string::npos ? 0 : slash + 1);
    FileHandle movie_dir;
    {
      std::lock_guard lock(impl.mutex);
      movie_dir = open_subdirectory(impl.dir_fd.get(), slash == std::string::npos ? "" : relative.substr(0, slash), false,
                                    impl.dir);
    }
    // The reader opens by path: the movie must be a regular file inside the database, not a link.
    struct stat st{};
    if (::fstatat(movie_dir.get(), leaf.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0)
      throw FileError(path.string(), "missing: the database's last checkpoint has " + std::to_string(frames) +
                                         " frames in every movie; cannot resume it");
    if (!S_ISREG(st.st_mode)) throw FileError(path.string(), "is not a regular file; cannot resume it");
    std::unique_ptr<video::MovieReader> old;
    try {
      old = std::make_unique<video::MovieReader>(path.string());
    } catch (const Error& e) {
      throw FileError(path.string(), std::string("unreadable (") + e.what() + "); cannot resume it");
    }
    if (old->frame_count() < frames)
      throw FileError(path.string(), "holds " + std::to_string(old->frame_count()) + " readable frames, the database's last "
                                         "checkpoint " + std::to_string(frames) + "; cannot resume it");
    const std::string temp = leaf + ".resume";
    FileHandle file = open_for_writing(movie_dir.get(), temp, true, "movie", path.parent_path());
    std::optional<video::MovieIdentity> identity;
    if (man.frame_checks.recorded()) identity = movie_identity(man, camera, task);
    auto writer = std::make_unique<video::MovieWriter>(file.release(), path.string(), man.image.width, man.image.height,
                                                       man.video, identity, man.frame_checks.binds_parameter_sets());
    writer->copy_frames(*old, frames);
    writer->flush();
    if (::renameat(movie_dir.get(), temp.c_str(), movie_dir.get(), leaf.c_str()) != 0)
      throw FileError(path.string(), std::string("cannot replace the movie by its continued copy: ") + std::strerror(errno));
    s.writer = std::move(writer);
  };
  Impl& m = *impl;
  const int tasks = m.manifest.task_count();
  if (!options.writes_manifest) {
    const auto [layout, segment] = layout_on_disk(m.dir_fd.get(), dir);
    m.manifest.layout = layout;
    if (layout == Layout::packed) m.manifest.packs = {segment};
  }
  try {
    if (m.manifest.layout == Layout::packed) {
      // Each owned stream continues from its indexed fragments: a fragment holding the seam is cut by
      // copying its frames before the seam into the new segment's first fragment.
      const Database old_db = Database::open(dir);
      if (old_db.manifest().layout != Layout::packed)
        throw FileError(dir.string(), "resume: the manifest on disk is not packed; cannot continue its packs");
      parallel_for(std::int64_t(m.streams.size()), m.streams.size() > 16 ? 0 : 1, [&](std::int64_t i) {
        const int camera = owned[std::size_t(i / tasks)], task = int(i % tasks);
        Impl::Stream& s = m.streams[std::size_t(i)];
        s.frames = s.flushed = frames;
        if (frames == 0) return;
        const PackedStream ps = old_db.packed_stream(camera, task);
        if (ps.frames() < frames)
          throw FileError(dir.string(), "resume: stream camera " + std::to_string(camera) + ", task " + std::to_string(task) +
                                            " holds " + std::to_string(ps.frames()) + " indexed frames, the last checkpoint " +
                                            std::to_string(frames) + "; cannot resume it");
        for (const auto& piece : ps.pieces) {
          if (piece.frames == 0 || piece.first_frame >= frames || piece.first_frame + piece.frames <= frames) continue;
          video::MovieReader reader(ps.file_pieces(), ps.pieces.front().file.string());
          std::vector<std::uint8_t> bytes;
          for (int f = piece.first_frame; f < frames; ++f) {
            reader.read_packet(f, bytes);
            s.pending.insert(s.pending.end(), bytes.begin(), bytes.end());
            s.pending_sizes.push_back(std::uint32_t(bytes.size()));
          }
          s.flushed = piece.first_frame;
        }
      });
      m.open_pack(m.manifest.packs.back().segment, frames);
    } else {
      parallel_for(std::int64_t(m.streams.size()), m.streams.size() > 16 ? 0 : 1, [&](std::int64_t i) {
        const int slot = int(i / tasks);
        resume_stream(m, owned[std::size_t(slot)], int(i % tasks), frames, m.streams[std::size_t(i)]);
      });
    }
    if (options.writes_manifest) {
      m.table = write_camera_table(dir, m.manifest);
      m.write_manifest(Status::running, frames);
    }
  } catch (...) {
    m.streams.clear();
    m.release_lock();
    throw;
  }
  if (!old_table.empty() && old_table != m.table.file) ::unlinkat(m.dir_fd.get(), old_table.c_str(), 0);
  return DatabaseWriter(std::move(impl));
}

// --- liveness ---

bool writer_is_alive(const fs::path& dir) {
  // No link, FIFO or device is opened (a FIFO planted at the lock would block a plain open forever).
  int fd = -1;
  try {
    fd = open_regular_file(open_directory(dir).get(), kLockFileName, 4096, "writer lock", dir, true).release();
  } catch (const Error&) {
    return false;  // not a lock any writer made: no live writer
  }
  if (fd < 0) return false;  // no lock file: the writer finished or never started
  bool alive;
  if (::flock(fd, LOCK_SH | LOCK_NB) == 0) {
    alive = false;  // nobody holds the writer's exclusive lock
    ::flock(fd, LOCK_UN);
  } else if (errno == EWOULDBLOCK) {
    alive = true;
  } else {
    // No flock here: trust the pid when the writer ran on this host; elsewhere assume it lives.
    char buf[300] = {};
    const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
    long pid = 0;
    char host[256] = {};
    alive = true;
    if (n > 0 && std::sscanf(buf, "%ld %255s", &pid, host) == 2 && host_name() == host)
      alive = pid > 0 && (::kill(pid_t(pid), 0) == 0 || errno == EPERM);
  }
  ::close(fd);
  return alive;
}

}  // namespace panoptes::store
