#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <mutex>

#include "player/engine_impl.hpp"

namespace panoptes::player {

// ---- the workers and their queue (Engine::Impl) ----

void Engine::Impl::worker_loop() {
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

void Engine::Impl::start_workers() {
  const int n = options.prefetch ? options.prefetch_threads : 0;
  for (int i = 0; i < n; ++i) workers.emplace_back([this] { worker_loop(); });
}

void Engine::Impl::stop_workers() {
  {
    std::lock_guard lock(job_mutex);
    stopping = true;
  }
  job_ready.notify_all();
  for (auto& w : workers) w.join();
  workers.clear();
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
void Engine::Impl::schedule_prefetch() {
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

std::vector<Selection> Engine::Impl::prefetch_plan() const {
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

// ---- the Engine's prefetch calls ----

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

}  // namespace panoptes::player
