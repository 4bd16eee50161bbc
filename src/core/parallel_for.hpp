#pragma once
// One parallel-for for the thread pools outside the numerical loops (those use OpenMP): a database's
// streams written, flushed, checked, exported or imported side by side, each index on one thread.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace panoptes {

/// The threads parallel_for runs `n` items on when asked for `threads` (<= 0: one per hardware
/// thread): at least 1, at most n.
inline int parallel_threads(std::int64_t n, int threads) {
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  return int(std::min<std::int64_t>(threads, std::max<std::int64_t>(n, 1)));
}

/// Calls body(i) for every i in [0, n) on parallel_threads(n, threads) threads, each index once,
/// handed out in ascending order. The calling thread is one of them, unless `watch` is given: then it
/// calls watch() every `period` while the others work, until they end, an index failed or watch()
/// returns false (progress reports). After the first exception no further index is started; it is
/// rethrown here once every thread has stopped.
template <class Body>
void parallel_for(std::int64_t n, int threads, Body&& body, const std::function<bool()>& watch = {},
                  std::chrono::milliseconds period = std::chrono::milliseconds(100)) {
  threads = parallel_threads(n, threads);
  std::atomic<std::int64_t> next{0};
  std::atomic<int> running{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (std::int64_t i; (i = next.fetch_add(1)) < n;) {
      try {
        body(i);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;  // stop handing out work
      }
    }
    --running;
  };
  const bool watching = bool(watch);
  running = threads;
  std::vector<std::thread> pool;
  for (int t = watching ? 0 : 1; t < threads; ++t) pool.emplace_back(work);
  if (watching) {
    while (running.load() > 0 && watch()) {
      std::this_thread::sleep_for(period);
      std::lock_guard lock(error_mutex);
      if (error) break;
    }
  } else {
    work();
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace panoptes
