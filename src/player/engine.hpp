#pragma once
// The UI-free playback engine: a selection (camera, task, frame) over a movie database, a playback
// clock, navigation commands, background prefetch and a frame cache. No SDL, no ImGui: the window
// front end (module ui) and the headless mode drive the same engine.
//
// Threading: the command/query API (everything on Engine) is called from ONE thread (the display
// thread). Internally a small pool of prefetch threads decodes the streams the user may switch to
// next; a MovieReader is only ever used by one thread at a time (readers are checked out of a pool).
//
// Latency path of a switch: command → selection changes → current_frame() looks the new
// (camera, task, frame) up in the frame cache (a hit when prefetch got there first) → if a prefetch
// thread is decoding it right now, waits for that decode → else decodes it on the calling thread.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/vec3.hpp"
#include "player/keys.hpp"
#include "store/database.hpp"
#include "video/movie_reader.hpp"

namespace panoptes::player {

/// A source of time in seconds (monotonic, arbitrary origin). Injected so tests and the headless mode
/// run on a virtual clock; the default is std::chrono::steady_clock.
using TimeSource = std::function<double()>;

/// The wall-clock time source (steady_clock, seconds).
TimeSource steady_time_source();

/// A virtual clock for tests and headless runs: time only moves when set()/advance() is called.
class VirtualClock {
 public:
  double now() const { return now_; }
  void set(double seconds) { now_ = seconds; }
  void advance(double seconds) { now_ += seconds; }
  /// A TimeSource reading this clock (the clock must outlive every user of the source).
  TimeSource source() const { return [this] { return now_; }; }

 private:
  double now_ = 0;
};

/// Engine configuration.
struct EngineOptions {
  /// Maximum number of open MovieReaders (LRU pool). Must be ≥ prefetch_threads + 2.
  int reader_pool_capacity = 32;
  /// Frame cache memory cap in bytes; 0 = default_cache_bytes().
  std::size_t cache_bytes = 0;
  /// Background prefetch on/off (off: every switch decodes on the display path).
  bool prefetch = true;
  /// Prefetch threads (0 = off, same as prefetch = false).
  int prefetch_threads = 2;
  /// Nice increment of the prefetch threads relative to the process (0..19; Linux nice is per
  /// thread). Higher = prefetch yields to every other process too, and a display thread waiting for
  /// an in-flight prefetch decode then waits longer; 0 measured best under load (docs/player.md).
  int prefetch_nice = 0;
  /// Frames ahead (in the playback direction) prefetched for the current stream, beyond the next one.
  int read_ahead = 2;
  /// Prefetch the graph neighbours (left/right/up/down/in/out) of the selection.
  bool prefetch_cameras = true;
  /// Prefetch the task neighbours (next/previous task, ±1 on every parameter axis).
  bool prefetch_tasks = true;
  /// Start playing (true, like a video player) or paused.
  bool start_playing = true;
  /// Playback loops at the ends (L toggles).
  bool loop = true;
  /// While the database is `running` (a live writer), tick() calls refresh() every this many seconds
  /// of the playback clock, so new frames appear; 0 = never.
  double refresh_seconds = 1.0;
  /// Initial selection.
  int camera = 0, task = 0, frame = 0;
  /// Playback time source; empty = steady_time_source().
  TimeSource time_source;
};

/// min(1/8 of physical memory, 2 GiB), at least 64 MiB.
std::size_t default_cache_bytes();

/// What is shown: one stream at one frame.
struct Selection {
  int camera = 0;
  int task = 0;
  int frame = 0;
  bool operator==(const Selection&) const = default;
};

/// Health of the frame shown for a selection.
enum class FrameStatus {
  ok,          ///< decoded from the movie
  missing,     ///< the movie file does not exist
  unreadable,  ///< the movie exists but cannot be opened/decoded, or is truncated before this frame
  damaged,     ///< the decoder had to conceal damage in this frame (or a frame it predicts from)
};
std::string_view to_string(FrameStatus status);

/// A frame ready for display. When status != ok, `frame` is a generated placeholder (same size as the
/// database's images, dark red with large text naming the problem and the stream) and `message` says
/// what went wrong (naming the file). Never null.
struct ShownFrame {
  Selection selection;
  FrameStatus status = FrameStatus::ok;
  std::string message;
  std::shared_ptr<const video::YuvFrame> frame;
  bool cache_hit = false;  ///< served from the frame cache (no decode on the display path)
  double time = 0;         ///< simulation time of the frame (manifest times, else the frame index)
};

/// Direction of a graph move.
enum class Direction { left, right, up, down, in, out };
std::string_view to_string(Direction direction);

/// One camera/task switch as seen by the user: from the command to the new stream's frame being ready
/// (measured on the steady clock, whatever the playback time source).
struct SwitchRecord {
  Selection from, to;
  std::string command;   ///< e.g. "camera_right", "jump_to_camera", "snap", "next_task"
  double latency_ms = 0; ///< command → ShownFrame ready (includes waiting for/doing the decode)
  bool cache_hit = false;
};

/// Counters and timings since construction (or reset_statistics()).
struct Statistics {
  std::int64_t frames_shown = 0;        ///< current_frame() calls
  std::int64_t cache_hits = 0;          ///< shown frames served from the cache
  std::int64_t cache_misses = 0;        ///< shown frames decoded (or waited for) on the display path
  std::int64_t waited_for_prefetch = 0; ///< misses that waited for an in-flight prefetch decode
  std::int64_t prefetch_decodes = 0;    ///< frames decoded by prefetch threads
  std::int64_t display_decodes = 0;     ///< frames decoded on the display thread
  std::int64_t readers_opened = 0;      ///< MovieReaders opened (pool misses)
  std::int64_t readers_evicted = 0;     ///< readers closed by the pool's LRU bound
  std::int64_t cache_evictions = 0;     ///< frames dropped by the cache's memory cap
  std::int64_t placeholders_shown = 0;  ///< shown frames with status != ok
  std::size_t cache_bytes = 0;          ///< bytes held by the cache now
  std::size_t cache_capacity = 0;       ///< the cap
  int readers_open = 0;                 ///< readers in the pool now
  int reader_capacity = 0;
  /// Decode times in ms (any thread): every decode, or the most recent kMaxSamples in a long session
  /// (unordered then), so copying statistics stays cheap.
  std::vector<double> decode_ms;
  /// Switches in order: every one, or (in a long session) the most recent ones — at most kMaxSamples.
  std::vector<SwitchRecord> switches;
  static constexpr std::size_t kMaxSamples = 65536;
};

/// Percentile summary of a sample (empty sample → all zero).
struct Summary {
  std::size_t count = 0;
  double mean = 0, p50 = 0, p99 = 0, max = 0;
};
Summary summarize(std::vector<double> values);

/// Statistics as JSON: counters, decode-time and switch-latency summaries, and every switch.
nlohmann::json to_json(const Statistics& statistics);

/// The playback engine. Movable, not copyable. See the file comment for the threading rules.
class Engine {
 public:
  /// Opens the database lazily (manifest only). Throws FileError if dir is not a database, Error if
  /// it has no cameras/tasks or no complete frame yet, or options are invalid.
  Engine(const std::filesystem::path& dir, EngineOptions options = {});
  /// Uses an already opened database.
  Engine(store::Database database, EngineOptions options = {});
  ~Engine();  ///< Stops the prefetch threads.
  Engine(Engine&&) noexcept;
  Engine& operator=(Engine&&) noexcept;

  const store::Database& database() const;
  const store::Manifest& manifest() const;
  const EngineOptions& options() const;
  /// Frames playable: the database's frames_written (an interrupted database plays what it has),
  /// updated by refresh().
  int frame_count() const;
  /// For a database that is still being written: re-reads the manifest and takes over its frame count
  /// and times (cameras, tasks and graph must be unchanged), and forgets streams that were missing so
  /// they are tried again. Returns the new frame_count(). Throws FileError/Error if the manifest cannot
  /// be read or the database's shape changed; the engine is unchanged then. manifest() keeps the
  /// manifest read at construction (its frames_written/times are not updated); live_manifest() is the
  /// one read now.
  int refresh();
  /// The manifest as of construction or the last refresh(): what is recorded per frame (times, the
  /// fields' references that legends and value readouts scale by) for the frames that appeared since
  /// the database was opened. Shares the shape of manifest() (refresh() refuses a changed shape). The
  /// pointer stays valid however often the engine refreshes afterwards.
  std::shared_ptr<const store::Manifest> live_manifest() const;
  /// Effective status of the database at construction or the last refresh().
  store::Status status() const;
  /// Playback rate at speed ×1: the manifest's playback_fps if set, else its video fps.
  double fps() const;

  // ---- selection and playback -------------------------------------------------------------------
  Selection selection() const;
  /// Advances the playback clock to the time source's now (call once per displayed frame, before
  /// current_frame()). While playing, frame = start + floor((now - t0) · fps · speed) in the playback
  /// direction; at an end it wraps (loop) or stops and pauses.
  void tick();
  bool playing() const;
  /// Starts/stops the clock. Starting at the end of a non-looping run restarts from the other end.
  void set_playing(bool playing);
  /// Re-anchors the playback clock at the time source's now, keeping the position: a front end calls it
  /// once its first frame is on the screen, so that opening the window and decoding that frame (half a
  /// second on the paper's database) do not count as time played and the movie starts at its frame.
  void restart_clock();
  void toggle_playing();
  /// Playback speed factor, clamped to [0.25, 8].
  double speed() const;
  void set_speed(double speed);
  bool loop() const;
  void set_loop(bool loop);
  /// +1 forward, -1 backward.
  int direction() const;
  void set_direction(int direction);

  // ---- commands (each returns false and changes nothing if it cannot apply, e.g. no such edge) ----
  /// Executes an engine action (see keys.hpp); false for front-end-only actions or when impossible.
  bool apply(Action action);
  /// Moves along the navigation graph; false if the graph has no such edge from the current camera.
  bool navigate(Direction direction);
  /// The camera whose direction from its look-at point is nearest (largest cosine) to `direction`,
  /// among cameras on `shell` (-1 = any shell). O(cameras), no allocation. -1 if none.
  int nearest_camera(const Vec3& direction, int shell = -1) const;
  /// Switches to nearest_camera(direction, current shell) (for mouse drags); false if unchanged.
  bool snap_to_direction(const Vec3& direction);
  /// Switches camera; false if out of range or already selected.
  bool jump_to_camera(int camera);
  /// Switches task; false if out of range or already selected.
  bool set_task(int task);
  /// Next/previous task (wrapping around).
  bool next_task();
  bool previous_task();
  /// Moves to the task at the same positions as the current one on every parameter axis except
  /// `axis`, where the index moves by delta; false if there is none.
  bool step_axis(int axis, int delta);
  /// The axis PageUp/PageDown step (index into manifest().axes; -1 if the database has no axes).
  int active_axis() const;
  void set_active_axis(int axis);
  /// Pauses and moves `delta` frames (clamped, or wrapped when looping).
  void step_frame(int delta);
  /// Moves to frame (clamped to [0, frame_count()-1]) keeping the play state.
  void seek(int frame);

  // ---- display --------------------------------------------------------------------------------
  /// The frame for the current selection, decoded or placeholder. Blocks only when the frame is not
  /// cached (then it waits for an in-flight prefetch decode or decodes itself). Records the switch
  /// latency when the selection's stream changed since the previous call. Never throws for stream
  /// problems (they become placeholders).
  ShownFrame current_frame();
  /// The frame of any selection, through the cache (does not count as shown, no switch record).
  ShownFrame frame_at(const Selection& selection);
  /// What the prefetch threads are asked to decode for the current selection and play state, in
  /// priority order (the queue current_frame() schedules): paused, the neighbours' current frame
  /// first; playing, the current stream's next frame and the neighbours' next frame first. Camera
  /// neighbours are ordered by the view direction hint when one is set.
  std::vector<Selection> prefetch_plan() const;
  /// The world direction the viewer faces (360° look-around): graph neighbours whose displacement is
  /// best aligned with it are prefetched first, so a walk ahead hits the cache even when the machine
  /// cannot decode all neighbours in time. A zero/non-finite vector clears the hint (graph order).
  void set_view_direction(const Vec3& direction);
  /// Blocks until the prefetch threads have nothing queued (tests, benchmarks). Returns immediately
  /// when prefetch is off.
  void wait_prefetch_idle();
  /// True if the frame is in the cache now.
  bool is_cached(const Selection& selection) const;

  // ---- statistics -----------------------------------------------------------------------------
  Statistics statistics() const;
  /// Clears the counters and samples; readers_opened/evicted and cache_evictions count since
  /// construction (they belong to the pool and the cache).
  void reset_statistics();
  /// Writes to_json(statistics()) to path (pretty-printed). Throws FileError on failure.
  void write_statistics(const std::filesystem::path& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A placeholder frame of width x height saying `title` (e.g. "STREAM MISSING") and `detail` (e.g.
/// "camera 3 task 1"), in YUV 4:2:0 like decoded frames.
video::YuvFrame make_placeholder(int width, int height, std::string_view title, std::string_view detail);

}  // namespace panoptes::player
