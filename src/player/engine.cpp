#include "player/engine.hpp"
#include "player/playback_rule.hpp"

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
#include "player/engine_impl.hpp"
#include "player/frame_cache.hpp"
#include "player/reader_pool.hpp"

namespace panoptes::player {

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
void Engine::restart_clock() { impl_->anchor_time = impl_->now(); }
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

}  // namespace panoptes::player
