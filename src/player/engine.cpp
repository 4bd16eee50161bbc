#include "player/engine.hpp"
#include "player/playback_rule.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <thread>

#include "camera/navigation.hpp"
#include "core/error.hpp"
#include "player/frame_cache.hpp"
#include "player/reader_pool.hpp"

namespace panoptes::player {
namespace {

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}


}  // namespace

TimeSource steady_time_source() { return [] { return steady_seconds(); }; }

std::size_t default_cache_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  const std::size_t two_gib = std::size_t(2) << 30, min_bytes = std::size_t(64) << 20;
  if (pages <= 0 || page <= 0) return std::size_t(512) << 20;
  const std::size_t eighth = std::size_t(pages) * std::size_t(page) / 8;
  return std::max(min_bytes, std::min(eighth, two_gib));
}

std::string_view to_string(FrameStatus status) {
  switch (status) {
    case FrameStatus::ok: return "ok";
    case FrameStatus::missing: return "missing";
    case FrameStatus::unreadable: return "unreadable";
    case FrameStatus::damaged: return "damaged";
  }
  return "unknown";
}

std::string_view to_string(Direction direction) {
  switch (direction) {
    case Direction::left: return "left";
    case Direction::right: return "right";
    case Direction::up: return "up";
    case Direction::down: return "down";
    case Direction::in: return "in";
    case Direction::out: return "out";
  }
  return "unknown";
}

Summary summarize(std::vector<double> values) {
  Summary s;
  s.count = values.size();
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  double sum = 0;
  for (double v : values) sum += v;
  s.mean = sum / double(values.size());
  const auto pick = [&](double q) {
    const std::size_t i = std::min(values.size() - 1, std::size_t(std::ceil(q * double(values.size()))) - (q > 0 ? 1 : 0));
    return values[i];
  };
  s.p50 = pick(0.50);
  s.p99 = pick(0.99);
  s.max = values.back();
  return s;
}

nlohmann::json to_json(const Statistics& st) {
  const auto summary = [](const std::vector<double>& v) {
    const Summary s = summarize(v);
    return nlohmann::json{{"count", s.count}, {"mean_ms", s.mean}, {"p50_ms", s.p50}, {"p99_ms", s.p99}, {"max_ms", s.max}};
  };
  std::vector<double> latencies;
  latencies.reserve(st.switches.size());
  nlohmann::json switches = nlohmann::json::array();
  for (const auto& s : st.switches) {
    latencies.push_back(s.latency_ms);
    switches.push_back({{"command", s.command},
                        {"from", {{"camera", s.from.camera}, {"task", s.from.task}, {"frame", s.from.frame}}},
                        {"to", {{"camera", s.to.camera}, {"task", s.to.task}, {"frame", s.to.frame}}},
                        {"latency_ms", s.latency_ms},
                        {"cache_hit", s.cache_hit}});
  }
  return {{"frames_shown", st.frames_shown},
          {"cache", {{"hits", st.cache_hits},
                     {"misses", st.cache_misses},
                     {"waited_for_prefetch", st.waited_for_prefetch},
                     {"evictions", st.cache_evictions},
                     {"bytes", st.cache_bytes},
                     {"capacity_bytes", st.cache_capacity}}},
          {"decodes", {{"prefetch", st.prefetch_decodes}, {"display", st.display_decodes}}},
          {"readers", {{"opened", st.readers_opened}, {"evicted", st.readers_evicted},
                       {"open", st.readers_open}, {"capacity", st.reader_capacity}}},
          {"placeholders_shown", st.placeholders_shown},
          {"decode_time", summary(st.decode_ms)},
          {"switch_latency", summary(latencies)},
          {"switches", switches}};
}

// ------------------------------------------------------------------------------------------------

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
      const bool exists = std::filesystem::exists(path, ec);
      const FrameStatus status = exists ? FrameStatus::unreadable : FrameStatus::missing;
      const std::string message = exists ? std::string(e.what()) : path.string() + ": movie file is missing";
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

  // ---- prefetch ----
  void worker_loop() {
    // Linux nice values are per thread, so this lowers only this worker (best effort). Default 0: the
    // display thread sleeps between frames, and CFS already runs a waking sleeper ahead of busy
    // threads of equal nice. A niced worker, by contrast, is starved by every other process on a
    // loaded machine, and the display thread then waits for its in-flight decode (priority
    // inversion): with nice 5 and 4 extra busy loops on 2 cores, switch hits fell to 30-50 % and the
    // display call's p99 rose to 140-215 ms (nice 0: 67-70 %, 56-69 ms; equal when not loaded).
    if (options.prefetch_nice > 0)
      ::setpriority(PRIO_PROCESS, ::id_t(::syscall(SYS_gettid)),
                    std::min(19, ::getpriority(PRIO_PROCESS, 0) + options.prefetch_nice));
    for (;;) {
      Selection s;
      {
        std::unique_lock lock(job_mutex);
        job_ready.wait(lock, [&] { return stopping || job_next < jobs.size(); });
        if (stopping) return;
        s = jobs[job_next++];
        ++busy;
      }
      const FrameKey key{stream_of(s.camera, s.task), s.frame};
      std::shared_ptr<const video::YuvFrame> cached;
      if (cache.claim(key, cached) == FrameCache::Claim::claimed) {
        Decoded d = decode(s, true);
        cache.finish(key, std::move(d.frame));
      }
      {
        std::lock_guard lock(job_mutex);
        --busy;
        if (busy == 0 && job_next >= jobs.size()) job_idle.notify_all();
      }
    }
  }

  void start_workers() {
    const int n = options.prefetch ? options.prefetch_threads : 0;
    for (int i = 0; i < n; ++i) workers.emplace_back([this] { worker_loop(); });
  }

  void stop_workers() {
    {
      std::lock_guard lock(job_mutex);
      stopping = true;
    }
    job_ready.notify_all();
    for (auto& w : workers) w.join();
    workers.clear();
  }

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

  // Replaces the prefetch queue with the neighbourhood of the selection. Order = priority, and it
  // depends on what a switch would show next:
  //  - playing: the current stream's next frame (playback), then every neighbour at the next frame
  //    (what a switch during playback shows), then the current stream's further read-ahead, then the
  //    neighbours at the current frame. Neighbours come before the read-ahead because the read-ahead
  //    frames are queued again at the front on the following ticks, while a neighbour's next frame is
  //    needed within one display period or never: under load (workers starved) this raised switch cache
  //    hits from 47-70 % to 77 % (bench/player_bench BM_SwitchLatency with 4 extra busy loops on 2 cores).
  //  - paused: a switch shows the neighbours' CURRENT frame, so those come first, then the current
  //    stream's next frames (a frame step), then the neighbours' next frames (play, then switch). With
  //    the playing order the paused walks through 1920x960 360° streams waited for 9 useless decodes
  //    before the 6 they needed and missed every first visit (bench/inside_bench BM_WalkLatency).
  // Camera neighbours are ranked by how well their direction from this camera agrees with the view
  // direction hint (set_view_direction), so the camera ahead is decoded first when the machine cannot
  // decode all of them in time.
  void schedule_prefetch() {
    if (workers.empty()) return;
    if (scheduled_valid && scheduled == sel) return;
    scheduled = sel;
    scheduled_valid = true;
    std::vector<Selection> list = prefetch_plan();
    {
      std::lock_guard lock(job_mutex);
      jobs = std::move(list);
      job_next = 0;
    }
    job_ready.notify_all();
  }

  std::vector<Selection> prefetch_plan() const {
    std::vector<Selection> ahead;  // the current stream's next frames
    const int next = next_frame();
    int f = sel.frame;
    for (int k = 0; k <= options.read_ahead; ++k) {
      f = (k == 0) ? next : wrap_frame(f + dir * std::max(1, int(std::lround(speed_factor))));
      ahead.push_back({sel.camera, sel.task, f});
    }
    std::vector<std::pair<int, int>> cams;  // (rank, camera): graph neighbours, best view alignment first
    if (options.prefetch_cameras && !db.manifest().graph.empty()) {
      const auto& man = db.manifest();
      const auto& n = man.graph.neighbours[std::size_t(sel.camera)];
      const Vec3 here = man.cameras[std::size_t(sel.camera)].position;
      int slot = 0;
      // The camera the opposite arrow key retraces to (MoveTrail) is a neighbour too, after the graph's.
      for (int c : {n.left, n.right, n.up, n.down, n.in, n.out, trail.previous(sel.camera)}) {
        ++slot;
        if (c < 0 || c == sel.camera || c >= cameras) continue;
        int rank = slot;
        if (has_view_hint) {
          const Vec3 step = man.cameras[std::size_t(c)].position - here;
          const double len = norm(step);
          // -1000..1000 by cosine; ties keep the graph order.
          if (len > 0) rank = int(std::lround(-1000.0 * dot(step, view_hint) / len)) * 8 + slot;
        }
        if (std::none_of(cams.begin(), cams.end(), [&](const auto& p) { return p.second == c; })) cams.emplace_back(rank, c);
      }
      std::sort(cams.begin(), cams.end());
    }
    std::vector<std::pair<int, int>> streams;  // (camera, task) neighbours in priority order
    for (const auto& [rank, c] : cams) streams.emplace_back(c, sel.task);
    if (options.prefetch_tasks && tasks > 1) {
      std::vector<std::pair<int, int>> ts;
      ts.emplace_back(sel.camera, (sel.task + 1) % tasks);
      ts.emplace_back(sel.camera, (sel.task + tasks - 1) % tasks);
      const auto& m = db.manifest();
      for (const auto& a : m.axes)
        for (int d : {1, -1}) {
          const int t = m.step_task_on_axis(sel.task, a.name, d);
          if (t >= 0) ts.emplace_back(sel.camera, t);
        }
      for (const auto& p : ts)
        if (p.second != sel.task && std::find(streams.begin(), streams.end(), p) == streams.end()) streams.push_back(p);
    }
    std::vector<Selection> plan;
    plan.reserve(ahead.size() + 2 * streams.size());
    const auto add_neighbours = [&](int frame) {
      for (const auto& [c, t] : streams) plan.push_back({c, t, frame});
    };
    if (is_playing) {
      plan.push_back(ahead.front());
      add_neighbours(next);
      plan.insert(plan.end(), ahead.begin() + 1, ahead.end());
      add_neighbours(sel.frame);
    } else {
      add_neighbours(sel.frame);
      plan.insert(plan.end(), ahead.begin(), ahead.end());
      add_neighbours(next);
    }
    return plan;
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

// ------------------------------------------------------------------------------------------------

Engine::Engine(const std::filesystem::path& dir, EngineOptions options)
    : Engine(store::Database::open(dir), std::move(options)) {}

Engine::Engine(store::Database database, EngineOptions options) {
  const std::string where = database.dir().string();
  if (database.camera_count() == 0) throw Error(where + ": the database has no cameras");
  if (database.task_count() == 0) throw Error(where + ": the database has no tasks");
  if (database.frame_count() <= 0)
    throw Error(where + ": the database has no complete frame yet (status " +
                std::string(store::to_string(database.status())) + ", frames_written 0)");
  if (options.prefetch_threads < 0 || options.prefetch_threads > 64)
    throw Error("prefetch threads must be in 0..64, got " + std::to_string(options.prefetch_threads));
  const int threads = options.prefetch ? options.prefetch_threads : 0;
  if (options.reader_pool_capacity < threads + 2)
    throw Error("reader pool capacity " + std::to_string(options.reader_pool_capacity) +
                " is too small: it must be at least prefetch threads + 2 = " + std::to_string(threads + 2));
  if (options.prefetch_nice < 0 || options.prefetch_nice > 19)
    throw Error("prefetch nice must be in 0..19, got " + std::to_string(options.prefetch_nice));
  if (options.read_ahead < 0) throw Error("read_ahead must be >= 0, got " + std::to_string(options.read_ahead));
  if (options.camera < 0 || options.camera >= database.camera_count())
    throw Error(where + ": camera " + std::to_string(options.camera) + " out of range 0.." +
                std::to_string(database.camera_count() - 1));
  if (options.task < 0 || options.task >= database.task_count())
    throw Error(where + ": task " + std::to_string(options.task) + " out of range 0.." +
                std::to_string(database.task_count() - 1));
  if (options.frame < 0 || options.frame >= database.frame_count())
    throw Error(where + ": frame " + std::to_string(options.frame) + " out of range 0.." +
                std::to_string(database.frame_count() - 1));

  impl_ = std::make_unique<Impl>(std::move(database), std::move(options));
  Impl& m = *impl_;
  m.now = m.options.time_source ? m.options.time_source : steady_time_source();
  m.cameras = m.db.camera_count();
  m.tasks = m.db.task_count();
  m.frames = m.db.frame_count();
  m.times = m.db.manifest().times;
  m.db_status = m.db.status();
  // The database's preferred playback rate (a run of few snapshots lasts seconds), else its video rate.
  const auto& man = m.db.manifest();
  m.fps = man.playback_fps > 0 ? man.playback_fps : man.video.fps > 0 ? man.video.fps : 30;
  m.directions.reserve(std::size_t(m.cameras));
  m.shells.reserve(std::size_t(m.cameras));
  for (const auto& c : m.db.manifest().cameras) {
    m.directions.push_back(normalize(c.position - c.look_at));
    m.shells.push_back(c.labels.shell);
  }
  m.sel = {m.options.camera, m.options.task, m.options.frame};
  m.is_playing = m.options.start_playing;
  m.looping = m.options.loop;
  m.axis = m.db.manifest().axes.empty() ? -1 : 0;
  m.set_position(m.options.frame);
  m.stats.cache_capacity = m.cache.capacity();
  m.stats.reader_capacity = m.pool.capacity();
  m.start_workers();
}

Engine::~Engine() {
  if (impl_) impl_->stop_workers();
}
Engine::Engine(Engine&&) noexcept = default;
Engine& Engine::operator=(Engine&& other) noexcept {
  if (this != &other) {
    if (impl_) impl_->stop_workers();
    impl_ = std::move(other.impl_);
  }
  return *this;
}

const store::Database& Engine::database() const { return impl_->db; }
const store::Manifest& Engine::manifest() const { return impl_->db.manifest(); }
std::shared_ptr<const store::Manifest> Engine::live_manifest() const {
  return {impl_->live, &impl_->live->manifest()};  // aliasing: keeps that Database alive
}
const EngineOptions& Engine::options() const { return impl_->options; }
int Engine::frame_count() const { return impl_->frames; }
double Engine::fps() const { return impl_->fps; }
Selection Engine::selection() const { return impl_->sel; }
store::Status Engine::status() const { return impl_->db_status; }

int Engine::refresh() {
  Impl& m = *impl_;
  // A fresh Database object: the one the workers use is never modified (no locking needed).
  auto fresh_ptr = std::make_shared<const store::Database>(store::Database::open(m.db.dir()));
  const store::Database& fresh = *fresh_ptr;
  const auto& a = m.db.manifest();
  const auto& b = fresh.manifest();
  if (b.camera_count() != a.camera_count() || b.task_count() != a.task_count() || !(b.graph == a.graph) ||
      b.movie_pattern != a.movie_pattern || !(b.image == a.image))
    throw Error(m.db.dir().string() + ": the database changed shape (cameras, tasks, graph, image size or "
                "movie pattern) since it was opened; open it again");
  m.db_status = fresh.status();
  m.times = b.times;
  m.live = std::move(fresh_ptr);
  if (fresh.frame_count() > 0 && fresh.frame_count() != m.frames) {
    m.frames = fresh.frame_count();
    m.scheduled_valid = false;
    m.pool.invalidate();  // open readers index only the frames that existed when they were opened
    if (m.sel.frame >= m.frames) m.set_position(m.frames - 1);
  }
  {
    std::lock_guard lock(m.bad_mutex);
    m.bad_streams.clear();
  }
  return m.frames;
}
void Engine::tick() {
  Impl& m = *impl_;
  // A database still being written grows: take over its new frames now and then (on the playback
  // clock, so headless runs refresh at the same frames on every machine).
  if (m.db_status == store::Status::running && m.options.refresh_seconds > 0) {
    const double t = m.now();
    if (t - m.last_refresh >= m.options.refresh_seconds) {
      m.last_refresh = t;
      try {
        refresh();
      } catch (const Error&) {
        // A manifest caught mid-replace or a writer gone wrong: keep playing what we have.
      }
    }
  }
  m.tick();
}
bool Engine::playing() const { return impl_->is_playing; }

void Engine::set_playing(bool playing) {
  Impl& m = *impl_;
  if (playing == m.is_playing) return;
  m.tick();  // freeze the position reached so far
  m.is_playing = playing;
  m.scheduled_valid = false;  // the prefetch order depends on the play state
  // Like a video player: play at the end (without loop) starts again from the other end.
  if (playing && !m.looping && m.sel.frame == (m.dir > 0 ? m.frames - 1 : 0) && m.frames > 1)
    m.set_position(m.dir > 0 ? 0 : m.frames - 1);
  m.anchor_time = m.now();
}
void Engine::toggle_playing() { set_playing(!impl_->is_playing); }
double Engine::speed() const { return impl_->speed_factor; }
void Engine::set_speed(double speed) {
  Impl& m = *impl_;
  if (!std::isfinite(speed)) return;
  m.tick();
  m.speed_factor = std::clamp(speed, kSpeedMin, kSpeedMax);
}
bool Engine::loop() const { return impl_->looping; }
void Engine::set_loop(bool loop) { impl_->looping = loop; }
int Engine::direction() const { return impl_->dir; }
void Engine::set_direction(int direction) {
  Impl& m = *impl_;
  m.tick();
  m.dir = direction < 0 ? -1 : 1;
}

bool Engine::apply(Action action) {
  Impl& m = *impl_;
  switch (action) {
    case Action::play_pause: toggle_playing(); return true;
    case Action::frame_forward: step_frame(1); return true;
    case Action::frame_back: step_frame(-1); return true;
    case Action::first_frame: seek(0); return true;
    case Action::last_frame: seek(m.frames - 1); return true;
    case Action::toggle_loop: set_loop(!m.looping); return true;
    case Action::faster: {
      const double before = m.speed_factor;
      set_speed(m.speed_factor * kFasterFactor);
      return m.speed_factor != before;
    }
    case Action::slower: {
      const double before = m.speed_factor;
      set_speed(m.speed_factor / kFasterFactor);
      return m.speed_factor != before;
    }
    case Action::speed_up:
    case Action::speed_down:
    case Action::speed_reset: {
      const double before = m.speed_factor;
      set_speed(action == Action::speed_reset ? 1.0 : action == Action::speed_up ? m.speed_factor * kFineSpeedFactor : m.speed_factor / kFineSpeedFactor);
      return m.speed_factor != before;
    }
    case Action::reverse: set_direction(-m.dir); return true;
    case Action::camera_left: return navigate(Direction::left);
    case Action::camera_right: return navigate(Direction::right);
    case Action::camera_up: return navigate(Direction::up);
    case Action::camera_down: return navigate(Direction::down);
    case Action::shell_in: return navigate(Direction::in);
    case Action::shell_out: return navigate(Direction::out);
    case Action::next_task: return next_task();
    case Action::previous_task: return previous_task();
    case Action::task_1: case Action::task_2: case Action::task_3: case Action::task_4: case Action::task_5:
    case Action::task_6: case Action::task_7: case Action::task_8: case Action::task_9:
      return m.select(m.sel.camera, int(action) - int(Action::task_1), std::string(to_string(action)));
    case Action::axis_up: return m.axis >= 0 && step_axis(m.axis, 1);
    case Action::axis_down: return m.axis >= 0 && step_axis(m.axis, -1);
    case Action::next_axis:
    case Action::previous_axis: {
      if (m.axis < 0) return false;
      const int n = int(manifest().axes.size());
      m.axis = (m.axis + (action == Action::next_axis ? 1 : n - 1)) % n;
      return true;
    }
    default: return false;
  }
}

bool Engine::navigate(Direction direction) {
  Impl& m = *impl_;
  if (m.db.manifest().graph.empty()) return false;
  const auto& n = m.db.manifest().graph.neighbours[std::size_t(m.sel.camera)];
  int target = -1;
  camera::Move move = camera::Move::right;
  switch (direction) {
    case Direction::left: target = n.left, move = camera::Move::left; break;
    case Direction::right: target = n.right, move = camera::Move::right; break;
    case Direction::up: target = n.up, move = camera::Move::up; break;
    case Direction::down: target = n.down, move = camera::Move::down; break;
    case Direction::in: target = n.in, move = camera::Move::in; break;
    case Direction::out: target = n.out, move = camera::Move::out; break;
  }
  // The opposite of the last move(s) retraces them (camera/navigation.hpp, MoveTrail).
  target = m.trail.next(m.sel.camera, move, target);
  return m.select(target, m.sel.task, "camera_" + std::string(to_string(direction)));
}

int Engine::nearest_camera(const Vec3& direction, int shell) const {
  const Impl& m = *impl_;
  const Vec3 d = normalize(direction);
  if (!(norm(d) > 0)) return -1;
  int best = -1;
  double best_dot = -2;
  const std::size_t n = m.directions.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (shell >= 0 && m.shells[i] != shell) continue;
    const double c = dot(m.directions[i], d);
    if (c > best_dot) best_dot = c, best = int(i);
  }
  return best;
}

bool Engine::snap_to_direction(const Vec3& direction) {
  Impl& m = *impl_;
  const int c = nearest_camera(direction, m.shells[std::size_t(m.sel.camera)]);
  if (c >= 0 && c != m.sel.camera) m.trail.clear();  // a drag is not an arrow move: nothing to retrace
  return c >= 0 && m.select(c, m.sel.task, "snap");
}

bool Engine::jump_to_camera(int camera) {
  if (camera != impl_->sel.camera) impl_->trail.clear();
  return impl_->select(camera, impl_->sel.task, "jump_to_camera");
}
bool Engine::set_task(int task) { return impl_->select(impl_->sel.camera, task, "set_task"); }
bool Engine::next_task() {
  Impl& m = *impl_;
  return m.select(m.sel.camera, (m.sel.task + 1) % m.tasks, "next_task");
}
bool Engine::previous_task() {
  Impl& m = *impl_;
  return m.select(m.sel.camera, (m.sel.task + m.tasks - 1) % m.tasks, "previous_task");
}
bool Engine::step_axis(int axis, int delta) {
  Impl& m = *impl_;
  const auto& axes = m.db.manifest().axes;
  if (axis < 0 || axis >= int(axes.size()) || delta == 0) return false;
  const int t = m.db.manifest().step_task_on_axis(m.sel.task, axes[std::size_t(axis)].name, delta);
  return t >= 0 && m.select(m.sel.camera, t, "axis_" + axes[std::size_t(axis)].name);
}
int Engine::active_axis() const { return impl_->axis; }
void Engine::set_active_axis(int axis) {
  if (axis >= 0 && axis < int(manifest().axes.size())) impl_->axis = axis;
}

void Engine::step_frame(int delta) {
  Impl& m = *impl_;
  m.tick();
  m.is_playing = false;
  m.scheduled_valid = false;
  m.set_position(m.wrap_frame(m.sel.frame + delta));
}

void Engine::seek(int frame) {
  Impl& m = *impl_;
  m.set_position(std::clamp(frame, 0, m.frames - 1));
}

ShownFrame Engine::current_frame() {
  Impl& m = *impl_;
  const Selection s = m.sel;
  bool hit = false, waited = false;
  Impl::Decoded d = m.fetch(s, hit, waited);
  ShownFrame out = m.make_shown(s, std::move(d), hit);
  const std::int64_t stream = m.stream_of(s.camera, s.task);
  {
    std::lock_guard lock(m.stats_mutex);
    ++m.stats.frames_shown;
    ++(hit ? m.stats.cache_hits : m.stats.cache_misses);
    if (waited) ++m.stats.waited_for_prefetch;
    if (out.status != FrameStatus::ok) ++m.stats.placeholders_shown;
    if (m.switch_pending) {
      if (stream != m.last_stream) {
        SwitchRecord r;
        r.from = m.switch_from;
        r.to = s;
        r.command = m.switch_command;
        r.latency_ms = (steady_seconds() - m.switch_start) * 1e3;
        r.cache_hit = hit;
        if (m.stats.switches.size() >= Statistics::kMaxSamples)
          m.stats.switches.erase(m.stats.switches.begin(), m.stats.switches.begin() + Statistics::kMaxSamples / 2);
        m.stats.switches.push_back(std::move(r));
      }
      m.switch_pending = false;
    }
  }
  m.last_stream = stream;
  m.schedule_prefetch();
  return out;
}

ShownFrame Engine::frame_at(const Selection& selection) {
  Impl& m = *impl_;
  if (selection.camera < 0 || selection.camera >= m.cameras || selection.task < 0 || selection.task >= m.tasks ||
      selection.frame < 0 || selection.frame >= m.frames)
    throw Error("selection (camera " + std::to_string(selection.camera) + ", task " + std::to_string(selection.task) +
                ", frame " + std::to_string(selection.frame) + ") is out of range");
  bool hit = false, waited = false;
  return m.make_shown(selection, m.fetch(selection, hit, waited), hit);
}

std::vector<Selection> Engine::prefetch_plan() const { return impl_->prefetch_plan(); }

void Engine::set_view_direction(const Vec3& direction) {
  Impl& m = *impl_;
  const double len = norm(direction);
  const bool valid = std::isfinite(len) && len > 0;
  const Vec3 d = valid ? direction / len : Vec3{0, 0, 0};
  if (valid == m.has_view_hint && (!valid || dot(d, m.view_hint) > 0.999)) return;
  m.view_hint = d;
  m.has_view_hint = valid;
  m.scheduled_valid = false;  // re-rank on the next current_frame()
}

void Engine::wait_prefetch_idle() {
  Impl& m = *impl_;
  if (m.workers.empty()) return;
  std::unique_lock lock(m.job_mutex);
  m.job_idle.wait(lock, [&] { return m.busy == 0 && m.job_next >= m.jobs.size(); });
}

bool Engine::is_cached(const Selection& s) const {
  return impl_->cache.contains(FrameKey{impl_->stream_of(s.camera, s.task), s.frame});
}

Statistics Engine::statistics() const {
  const Impl& m = *impl_;
  Statistics st;
  {
    std::lock_guard lock(m.stats_mutex);
    st = m.stats;
  }
  st.cache_bytes = m.cache.bytes();
  st.cache_capacity = m.cache.capacity();
  st.cache_evictions = m.cache.evictions();
  st.readers_open = m.pool.open();
  st.reader_capacity = m.pool.capacity();
  st.readers_opened = m.pool.opened();
  st.readers_evicted = m.pool.evicted();
  return st;
}

void Engine::reset_statistics() {
  Impl& m = *impl_;
  std::lock_guard lock(m.stats_mutex);
  m.stats = Statistics{};
  m.decode_ring = 0;
}

void Engine::write_statistics(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw FileError(path.string(), "cannot create the statistics file");
  out << to_json(statistics()).dump(2) << '\n';
  if (!out) throw FileError(path.string(), "cannot write the statistics file");
}

}  // namespace panoptes::player
