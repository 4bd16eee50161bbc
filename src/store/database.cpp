// The movie database on disk, reading: Database (open, streams of either layout, frame checks,
// validation); database_writer.cpp writes it.
// Sections (each marked "// --- name ---" below):
//   reader      Database::open, streams resolved inside the directory, frame checks
//   packed      the packed layout's catalog of index headers, streams as byte ranges
//   validation  movie identities and validate_streams
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

namespace {

// True if `path` (canonical) lies inside `root` (canonical).
bool inside(const fs::path& root, const fs::path& path) {
  auto r = root.begin(), p = path.begin();
  for (; r != root.end(); ++r, ++p)
    if (p == path.end() || *r != *p) return false;
  return p != path.end();
}

}  // namespace

// --- reader ---

std::string_view to_string(StreamProblem::Kind kind) {
  switch (kind) {
    case StreamProblem::Kind::missing: return "missing";
    case StreamProblem::Kind::unreadable: return "unreadable";
    case StreamProblem::Kind::truncated: return "truncated";
    case StreamProblem::Kind::unsafe: return "unsafe";
    case StreamProblem::Kind::damaged: return "damaged";
  }
  return "unknown";
}

Database Database::open(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw FileError(dir.string(), "no such database directory");
  if (!fs::is_directory(dir, ec)) throw FileError(dir.string(), "not a directory (a database is a directory holding panoptes.json)");
  Database db;
  db.dir_ = dir;
  db.manifest_ = read_manifest(dir / kManifestFileName);
  db.stored_status_ = db.manifest_.status;
  if (db.manifest_.status == Status::running && !writer_is_alive(dir)) db.manifest_.status = Status::interrupted;
  if (db.packed()) db.packs_ = std::make_shared<PackCatalog>();
  return db;
}

fs::path Database::stream_path(int camera, int task) const {
  return dir_ / manifest_.stream_relative_path(camera, task);
}

namespace {

// A stream failure that knows its kind, so validate_streams can classify it without parsing text.
class StreamFileError : public FileError {
 public:
  StreamFileError(const fs::path& path, const std::string& what, StreamProblem::Kind kind)
      : FileError(path.string(), what), kind(kind) {}
  StreamProblem::Kind kind;
};

// The message of e without a leading "<path>: " (to avoid naming the same file twice).
std::string without_path(const Error& e, const std::string& path) {
  std::string m = e.what();
  if (m.rfind(path + ": ", 0) == 0) m.erase(0, path.size() + 2);
  return m;
}

// Resolves a stream's path and refuses anything that leaves the database directory.
fs::path resolve_stream(const fs::path& dir, const fs::path& path, int camera, int task) {
  const std::string which = " (stream camera " + std::to_string(camera) + ", task " + std::to_string(task) + ")";
  std::error_code ec;
  const fs::path root = fs::canonical(dir, ec);
  if (ec) {
    throw StreamFileError(dir, "cannot resolve the database directory: " + ec.message(), StreamProblem::Kind::missing);
  }
  const auto st = fs::symlink_status(path, ec);
  if (ec || !fs::exists(st)) {
    throw StreamFileError(path, "movie missing" + which, StreamProblem::Kind::missing);
  }
  // weakly_canonical does not need the target to exist, so a dangling link out is refused as unsafe
  // rather than reported as missing.
  const fs::path resolved = fs::weakly_canonical(path, ec);
  if (ec || !inside(root, resolved)) {
    throw StreamFileError(path,
                          "resolves to " + resolved.string() + ", outside the database directory " + root.string() +
                              "; refused" + which,
                          StreamProblem::Kind::unsafe);
  }
  if (!fs::exists(resolved, ec)) {
    throw StreamFileError(path, "movie missing (dangling link)" + which, StreamProblem::Kind::missing);
  }
  if (!fs::is_regular_file(resolved, ec)) {
    throw StreamFileError(path, "not a regular file" + which, StreamProblem::Kind::unreadable);
  }
  return resolved;
}

}  // namespace

// --- packed reading ---

// The index headers of a packed database's segments, read once on first use (Database::packs_).
struct PackCatalog {
  std::once_flag once;
  std::exception_ptr failure;
  struct Segment {
    std::vector<PackIndexInfo> packs;   // the ranks' indexes that exist
    std::vector<FileHandle> index_fds;  // open, one per pack
    std::vector<std::int32_t> owner;    // camera -> position in packs, -1 if none holds it
  };
  std::vector<Segment> segments;

  void load(const fs::path& dir, const Manifest& m) {
    std::error_code ec;
    const fs::path packs_dir = dir / kPackDirectory;
    FileHandle root = open_directory(dir);
    FileHandle pd;
    try {
      pd = open_subdirectory(root.get(), kPackDirectory, false, dir);
    } catch (const FileError&) {
      // No packs directory: a database killed before its first pack was made holds no stream.
    }
    for (const PackSegment& seg : m.packs) {
      Segment s;
      s.owner.assign(std::size_t(m.camera_count()), -1);
      for (int r = 0; pd && r < seg.ranks; ++r) {
        struct stat st{};
        if (::fstatat(pd.get(), pack_index_name(seg.segment, r).c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) continue;
        PackIndexInfo info = read_pack_index(pd.get(), packs_dir, seg.segment, r, m.task_count(), m.camera_count());
        for (int c : info.cameras) {
          if (s.owner[std::size_t(c)] >= 0)
            throw FileError(info.index.string(), "camera " + std::to_string(c) + " is also in " +
                                                     s.packs[std::size_t(s.owner[std::size_t(c)])].index.string() +
                                                     " (each camera belongs to one pack of a segment)");
          s.owner[std::size_t(c)] = std::int32_t(s.packs.size());
        }
        s.index_fds.push_back(open_regular_file(pd.get(), pack_index_name(seg.segment, r), std::uint64_t(1) << 40,
                                                "pack index", packs_dir));
        s.packs.push_back(std::move(info));
      }
      segments.push_back(std::move(s));
    }
    // Fragments of one stream come from several segments' packs behind one init segment: their
    // timing must agree.
    const PackIndexInfo* first = nullptr;
    for (const Segment& s : segments)
      for (const PackIndexInfo& p : s.packs) {
        if (!first) first = &p;
        if (p.timescale != first->timescale || p.frame_ticks != first->frame_ticks)
          throw FileError(p.index.string(), "time scale " + std::to_string(p.timescale) + "/" + std::to_string(p.frame_ticks) +
                                                " differs from " + first->index.string() + "'s " +
                                                std::to_string(first->timescale) + "/" + std::to_string(first->frame_ticks));
      }
  }
};

PackedStream Database::packed_stream(int camera, int task) const {
  if (!packed() || !packs_) throw Error(dir_.string() + ": not a packed database (its movies are files)");
  if (camera < 0 || camera >= camera_count() || task < 0 || task >= task_count())
    throw Error(dir_.string() + ": stream camera " + std::to_string(camera) + ", task " + std::to_string(task) +
                " out of range");
  PackCatalog& cat = *packs_;
  std::call_once(cat.once, [&] {
    try {
      cat.load(dir_, manifest_);
    } catch (...) {
      cat.failure = std::current_exception();
    }
  });
  if (cat.failure) std::rethrow_exception(cat.failure);
  std::vector<std::pair<const PackIndexInfo*, std::vector<PackRecord>>> per_segment;
  for (const PackCatalog::Segment& s : cat.segments) {
    const std::int32_t k = s.owner[std::size_t(camera)];
    if (k < 0) continue;
    per_segment.emplace_back(&s.packs[std::size_t(k)],
                             read_stream_records(s.index_fds[std::size_t(k)].get(), s.packs[std::size_t(k)], camera, task));
  }
  return assemble_stream(per_segment, camera, task);
}

std::unique_ptr<video::MovieReader> Database::stream(int camera, int task) const {
  if (packed()) return packed_reader(camera, task);
  const fs::path path = stream_path(camera, task);
  const fs::path resolved = resolve_stream(dir_, path, camera, task);
  const std::string which = " (stream camera " + std::to_string(camera) + ", task " + std::to_string(task) + ")";
  std::unique_ptr<video::MovieReader> reader;
  try {
    reader = std::make_unique<video::MovieReader>(resolved.string(), frame_checks(camera, task));
  } catch (const Error& e) {
    throw StreamFileError(path, "not a readable movie" + which + ": " + without_path(e, resolved.string()),
                          StreamProblem::Kind::unreadable);
  }
  if (reader->width() != manifest_.image.width || reader->height() != manifest_.image.height)
    reader->set_crop(manifest_.image.width, manifest_.image.height);
  if (reader->frame_count() < manifest_.frames_written)
    throw StreamFileError(path,
                    "truncated movie" + which + ": holds " + std::to_string(reader->frame_count()) + " of the " +
                        std::to_string(manifest_.frames_written) + " frames the manifest records",
                          StreamProblem::Kind::truncated);
  return reader;
}

std::unique_ptr<video::MovieReader> Database::packed_reader(int camera, int task) const {
  const std::string which = "stream camera " + std::to_string(camera) + ", task " + std::to_string(task);
  PackedStream ps;
  try {
    ps = packed_stream(camera, task);
  } catch (const FileError& e) {
    throw StreamFileError(dir_ / kPackDirectory, std::string("damaged pack index (") + which + "): " + e.what(),
                          StreamProblem::Kind::unreadable);
  }
  const fs::path where = ps.pieces.empty() ? dir_ / kPackDirectory : ps.pieces.front().file;
  if (ps.pieces.size() < 2 && manifest_.frames_written > 0)
    throw StreamFileError(where, "movie missing (" + which + ": no pack indexes a fragment of it)",
                          StreamProblem::Kind::missing);
  if (ps.pieces.empty()) throw StreamFileError(where, "movie missing (" + which + ")", StreamProblem::Kind::missing);
  const std::string name = where.string() + "#c" + std::to_string(camera) + "t" + std::to_string(task);
  std::unique_ptr<video::MovieReader> reader;
  try {
    reader = std::make_unique<video::MovieReader>(ps.file_pieces(), name, frame_checks(camera, task));
  } catch (const Error& e) {
    throw StreamFileError(name, std::string("not a readable movie (") + which + "): " + without_path(e, name),
                          StreamProblem::Kind::unreadable);
  }
  if (reader->width() != manifest_.image.width || reader->height() != manifest_.image.height)
    reader->set_crop(manifest_.image.width, manifest_.image.height);
  if (reader->frame_count() < manifest_.frames_written)
    throw StreamFileError(name,
                          "truncated movie (" + which + "): holds " + std::to_string(reader->frame_count()) + " of the " +
                              std::to_string(manifest_.frames_written) + " frames the manifest records",
                          StreamProblem::Kind::truncated);
  return reader;
}

video::FrameChecks Database::frame_checks(int camera, int task) const {
  video::FrameChecks checks;
  if (manifest_.frame_checks.recorded()) {
    checks.required = true;
    checks.identity = movie_identity(manifest_, camera, task);
    checks.parameter_sets = manifest_.frame_checks.binds_parameter_sets();
  }
  return checks;
}

std::vector<int> Database::damaged_frames(int camera, int task) const {
  std::vector<int> bad = stream(camera, task)->check_frames();
  bad.erase(std::lower_bound(bad.begin(), bad.end(), frame_count()), bad.end());
  return bad;
}

// --- validation ---
video::MovieIdentity movie_identity(const Manifest& manifest, int camera, int task) {
  video::MovieIdentity id{};
  const std::string& hex = manifest.frame_checks.database_id;
  for (std::size_t i = 0; i < 8 && 2 * i + 1 < hex.size(); ++i)
    id[i] = std::uint8_t(std::stoi(hex.substr(2 * i, 2), nullptr, 16));
  for (int i = 0; i < 4; ++i) {
    id[std::size_t(8 + i)] = std::uint8_t(std::uint32_t(camera) >> (24 - 8 * i));
    id[std::size_t(12 + i)] = std::uint8_t(std::uint32_t(task) >> (24 - 8 * i));
  }
  return id;
}

StreamReport Database::validate_streams(int threads, bool decode_all,
                                        const std::function<void(std::int64_t, std::int64_t)>& progress) const {
  const std::int64_t total = stream_count();
  const int tasks = task_count();
  StreamReport report;
  std::mutex mutex;
  std::atomic<std::int64_t> done{0}, bytes{0};
  std::atomic<bool> finished{false};
  std::thread reporter;
  if (progress)
    reporter = std::thread([&] {
      while (!finished.load()) {
        progress(done.load(), total);
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
    });
  auto check = [&](std::int64_t i) {
    const int camera = int(i / tasks), task = int(i % tasks);
    StreamProblem problem{camera, task, StreamProblem::Kind::missing, {}, {}};
    std::int64_t file_bytes = -1;
    try {
      if (packed()) {
        // The index alone tells whether every checkpointed frame is there (no movie is opened):
        // checking 10^6 streams reads their records, not 10^6 movies. A deep check decodes.
        const PackedStream ps = packed_stream(camera, task);
        std::int64_t n = 0;
        for (std::size_t k = 1; k < ps.pieces.size(); ++k) n += std::int64_t(ps.pieces[k].size);
        bytes += file_bytes = n;
        auto which = [&] { return "stream camera " + std::to_string(camera) + ", task " + std::to_string(task); };
        if (ps.pieces.size() < 2 && frame_count() > 0)
          throw StreamFileError(dir_ / kPackDirectory, "movie missing (" + which() + ": no pack indexes a fragment of it)",
                                StreamProblem::Kind::missing);
        if (ps.frames() < frame_count())
          throw StreamFileError(ps.pieces.front().file, "truncated movie (" + which() + "): its index names " +
                                                            std::to_string(ps.frames()) + " of the " +
                                                            std::to_string(frame_count()) + " frames the manifest records",
                                StreamProblem::Kind::truncated);
        if (!decode_all) {
          ++done;
          return;
        }
      } else {
        const fs::path resolved = resolve_stream(dir_, stream_path(camera, task), camera, task);
        std::error_code ec;
        const auto size = fs::file_size(resolved, ec);
        if (!ec) bytes += file_bytes = std::int64_t(size);
      }
      auto reader = stream(camera, task);
      problem.message.clear();
      if (decode_all) {
        video::YuvFrame frame;
        std::string first_error;
        for (int f = 0; f < frame_count(); ++f) {
          try {
            reader->read(f, frame);
          } catch (const Error& e) {  // damaged (concealed) or not decodable at all
            if (first_error.empty()) first_error = e.what();
            problem.damaged_frames.push_back(f);
          }
        }
        if (!problem.damaged_frames.empty()) {
          std::string list;
          for (std::size_t k = 0; k < problem.damaged_frames.size() && k < 20; ++k)
            list += (k ? ", " : "") + std::to_string(problem.damaged_frames[k]);
          if (problem.damaged_frames.size() > 20) list += ", ...";
          problem.kind = StreamProblem::Kind::damaged;
          problem.message = (packed() ? reader->path() : stream_path(camera, task).string()) + ": " +
                            std::to_string(problem.damaged_frames.size()) +
                            " of " + std::to_string(frame_count()) + " frames damaged (" + list + "); first: " +
                            first_error;
        }
      }
    } catch (const StreamFileError& e) {
      problem.message = e.what();
      problem.kind = e.kind;
    } catch (const Error& e) {
      problem.message = e.what();  // a decode failure of the last frame
      problem.kind = StreamProblem::Kind::unreadable;
    }
    // A database stopped before its first checkpoint records no frame: a movie not created yet, or
    // created but still empty (the writer was killed before its header), is not a problem then
    // (nothing it should hold is missing).
    if (frame_count() == 0 && (problem.kind == StreamProblem::Kind::missing ||
                               (problem.kind == StreamProblem::Kind::unreadable && file_bytes == 0)))
      problem.message.clear();
    if (!problem.message.empty()) {
      std::lock_guard lock(mutex);
      report.problems.push_back(std::move(problem));
    }
    ++done;
  };
  try {
    parallel_for(total, threads, check);
  } catch (...) {
    finished = true;
    if (reporter.joinable()) reporter.join();
    throw;
  }
  finished = true;
  if (reporter.joinable()) reporter.join();
  if (progress) progress(total, total);
  report.checked = total;
  report.bytes = bytes.load();
  std::sort(report.problems.begin(), report.problems.end(), [](const StreamProblem& a, const StreamProblem& b) {
    return a.camera != b.camera ? a.camera < b.camera : a.task < b.task;
  });
  return report;
}

}  // namespace panoptes::store
