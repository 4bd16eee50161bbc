#pragma once
// The engine's private state (not installed; included by engine*.cpp): engine.cpp the selection,
// clock, decoding and display path; engine_prefetch.cpp the prefetch threads and what they decode
// next; engine_statistics.cpp the statistics and their JSON.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "camera/navigation.hpp"
#include "player/engine.hpp"
#include "player/frame_cache.hpp"
#include "player/reader_pool.hpp"

namespace panoptes::player {

namespace engine_detail {

inline double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace engine_detail
using engine_detail::steady_seconds;

struct Engine::Impl {
  // The database as opened; the workers read it and it is never modified (refresh() needs no locks).
  std::shared_ptr<const store::Database> opened;
  const store::Database& db;
  // The database as last re-read by refresh() (the opened one until then, not a copy): the display
  // thread's view of what is recorded per frame.
  std::shared_ptr<const store::Database> live;
  EngineOptions options;
  TimeSource now;
  int cameras = 0, tasks = 0, frames = 0;
  std::vector<double> times;  // frame times, refreshed with frames
  camera::MoveTrail trail;    // arrow-key moves, so the opposite key retraces them
  store::Status db_status = store::Status::complete;
  double last_refresh = 0;  // playback-clock time of the last automatic refresh
  double fps = 30;
  std::vector<Vec3> directions;  // unit vectors look_at → position, for nearest_camera
  std::vector<int> shells;

  // Selection and clock (display thread only).
  Selection sel;
  double position = 0;      // frame position at anchor_time
  double anchor_time = 0;   // time source value the position refers to
  bool is_playing = true;
  double speed_factor = 1;
  int dir = 1;
  bool looping = true;
  int axis = -1;

  // Switch measurement (display thread only).
  bool switch_pending = false;
  double switch_start = 0;
  Selection switch_from;
  std::string switch_command;
  std::int64_t last_stream = -1;

  // Decoding machinery (shared with prefetch threads).
  ReaderPool pool;
  FrameCache cache;
  struct BadStream {
    FrameStatus status;
    std::string message;
  };
  mutable std::mutex bad_mutex;
  std::unordered_map<std::int64_t, BadStream> bad_streams;

  mutable std::mutex stats_mutex;
  Statistics stats;
  std::size_t decode_ring = 0;  // next slot to overwrite once decode_ms is full

  // Placeholder memo: regenerating a full-size placeholder every displayed frame would cost
  // milliseconds on the display path while a broken stream is shown.
  std::int64_t placeholder_stream = -1;
  FrameStatus placeholder_status = FrameStatus::ok;
  std::shared_ptr<const video::YuvFrame> placeholder;

  // Prefetch.
  std::mutex job_mutex;
  std::condition_variable job_ready, job_idle;
  std::vector<Selection> jobs;  // consumed from the front (index job_next)
  std::size_t job_next = 0;
  int busy = 0;
  bool stopping = false;
  std::vector<std::thread> workers;
  Selection scheduled{-1, -1, -1};
  bool scheduled_valid = false;
  Vec3 view_hint{0, 0, 0};  // unit world direction the viewer faces (set_view_direction)
  bool has_view_hint = false;

  Impl(store::Database database, EngineOptions opts)
      : opened(std::make_shared<const store::Database>(std::move(database))),
        db(*opened),
        live(opened),
        options(std::move(opts)),
        pool(db, std::max(1, options.reader_pool_capacity)),
        cache(options.cache_bytes ? options.cache_bytes : default_cache_bytes()) {}

  std::int64_t stream_of(int camera, int task) const { return std::int64_t(camera) * tasks + task; }

  struct Decoded {
    FrameStatus status = FrameStatus::ok;
    std::string message;
    std::shared_ptr<const video::YuvFrame> frame;
  };

  void mark_bad(std::int64_t stream, FrameStatus status, const std::string& message) {
    std::lock_guard lock(bad_mutex);
    bad_streams.emplace(stream, BadStream{status, message});
  }

  // Decodes one frame with a pooled reader. Any thread. Never throws for stream problems.
  Decoded decode(const Selection& s, bool prefetching) {
    const std::int64_t stream = stream_of(s.camera, s.task);
    {
      std::lock_guard lock(bad_mutex);
      if (auto it = bad_streams.find(stream); it != bad_streams.end()) return {it->second.status, it->second.message, nullptr};
    }
    std::unique_ptr<video::MovieReader> reader;
    try {
      reader = pool.acquire(s.camera, s.task);
    } catch (const std::exception& e) {
      std::error_code ec;
      const auto path = db.stream_path(s.camera, s.task);
      // A packed database has no file per stream: its reader says when the index names no fragment.
      const bool exists = db.packed() ? std::string(e.what()).find("movie missing") == std::string::npos
                                      : std::filesystem::exists(path, ec);
      const FrameStatus status = exists ? FrameStatus::unreadable : FrameStatus::missing;
      const std::string message =
          exists || db.packed() ? std::string(e.what()) : path.string() + ": movie file is missing";
      mark_bad(stream, status, message);
      return {status, message, nullptr};
    }
    if (s.frame >= reader->frame_count()) {
      const std::string message = reader->path() + ": truncated: holds " + std::to_string(reader->frame_count()) +
                                  " frames, frame " + std::to_string(s.frame) + " requested";
      pool.release(s.camera, s.task, std::move(reader));
      return {FrameStatus::unreadable, message, nullptr};
    }
    auto frame = std::make_shared<video::YuvFrame>();
    const double t0 = steady_seconds();
    try {
      reader->read(s.frame, *frame);
    } catch (const video::DamagedFrameError& e) {
      pool.release(s.camera, s.task, std::move(reader));
      return {FrameStatus::damaged, e.what(), nullptr};
    } catch (const std::exception& e) {
      pool.discard(std::move(reader));
      return {FrameStatus::unreadable, e.what(), nullptr};
    }
    const double ms = (steady_seconds() - t0) * 1e3;
    pool.release(s.camera, s.task, std::move(reader));
    {
      std::lock_guard lock(stats_mutex);
      auto& v = stats.decode_ms;
      if (v.size() < Statistics::kMaxSamples) {
        v.push_back(ms);
      } else {
        v[decode_ring++ % Statistics::kMaxSamples] = ms;
      }
      ++(prefetching ? stats.prefetch_decodes : stats.display_decodes);
    }
    return {FrameStatus::ok, {}, std::move(frame)};
  }

  // The frame of s through the cache. `waited`/`hit` report how it was obtained.
  Decoded fetch(const Selection& s, bool& hit, bool& waited) {
    const FrameKey key{stream_of(s.camera, s.task), s.frame};
    std::shared_ptr<const video::YuvFrame> frame;
    hit = waited = false;
    switch (cache.claim(key, frame)) {
      case FrameCache::Claim::cached:
        hit = true;
        return {FrameStatus::ok, {}, std::move(frame)};
      case FrameCache::Claim::in_flight:
        waited = true;
        if (auto f = cache.wait(key)) return {FrameStatus::ok, {}, std::move(f)};
        // The prefetch decode failed or did not fit the cache: decode here (uncached).
        return decode(s, false);
      case FrameCache::Claim::claimed: {
        Decoded d = decode(s, false);
        cache.finish(key, d.frame);
        return d;
      }
    }
    return {};
  }

  // ---- prefetch (engine_prefetch.cpp) ----
  void worker_loop();
  void start_workers();
  void stop_workers();
  // Replaces the prefetch queue with the neighbourhood of the selection (see engine_prefetch.cpp).
  void schedule_prefetch();
  std::vector<Selection> prefetch_plan() const;

  int wrap_frame(int f) const {
    if (looping) return ((f % frames) + frames) % frames;
    return std::clamp(f, 0, frames - 1);
  }

  // The frame shown one display period (1/fps) from now while playing, else the next in direction.
  int next_frame() const {
    const double step = is_playing ? speed_factor * dir : dir;
    int n = int(std::floor(double(sel.frame) + step + 1e-9));
    if (n == sel.frame) n += dir;
    return wrap_frame(n);
  }

  // ---- clock ----
  double current_position(double t) const {
    return is_playing ? position + (t - anchor_time) * fps * speed_factor * dir : position;
  }

  void set_position(double p) {
    anchor_time = now();
    position = p;
    sel.frame = std::clamp(int(std::floor(p + 1e-9)), 0, frames - 1);
  }

  void tick() {
    const double t = now();
    double p = current_position(t);
    position = p;
    anchor_time = t;
    if (p >= frames || p < 0) {
      if (looping) {
        p = std::fmod(p, double(frames));
        if (p < 0) p += frames;
      } else {
        p = p < 0 ? 0 : frames - 1;
        is_playing = false;
        scheduled_valid = false;
      }
      position = p;
    }
    sel.frame = std::clamp(int(std::floor(position + 1e-9)), 0, frames - 1);
  }

  void begin_switch(const Selection& from, const std::string& command) {
    if (!switch_pending) {
      switch_pending = true;
      switch_start = steady_seconds();
      switch_from = from;
    }
    switch_command = command;
  }

  bool select(int camera, int task, const std::string& command) {
    if (camera < 0 || camera >= cameras || task < 0 || task >= tasks) return false;
    if (camera == sel.camera && task == sel.task) return false;
    begin_switch(sel, command);
    sel.camera = camera;
    sel.task = task;
    return true;
  }

  std::shared_ptr<const video::YuvFrame> placeholder_for(const Selection& s, FrameStatus status) {
    const std::int64_t stream = stream_of(s.camera, s.task);
    if (!placeholder || placeholder_stream != stream || placeholder_status != status) {
      const int w = db.manifest().image.width, h = db.manifest().image.height;
      placeholder = std::make_shared<video::YuvFrame>(make_placeholder(
          w, h,
          status == FrameStatus::missing   ? "STREAM MISSING"
          : status == FrameStatus::damaged ? "FRAME DAMAGED"
                                           : "STREAM UNREADABLE",
          "CAMERA " + std::to_string(s.camera) + " TASK " + std::to_string(s.task)));
      placeholder_stream = stream;
      placeholder_status = status;
    }
    return placeholder;
  }

  ShownFrame make_shown(const Selection& s, Decoded d, bool hit) {
    ShownFrame out;
    out.selection = s;
    out.status = d.status;
    out.message = std::move(d.message);
    out.cache_hit = hit;
    out.time = s.frame < int(times.size()) ? times[std::size_t(s.frame)] : double(s.frame);
    if (d.status == FrameStatus::ok && d.frame) {
      out.frame = std::move(d.frame);
    } else {
      if (out.status == FrameStatus::ok) out.status = FrameStatus::unreadable;
      out.frame = placeholder_for(s, out.status);
    }
    return out;
  }
};

}  // namespace panoptes::player
