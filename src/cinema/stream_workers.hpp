#pragma once
// Streams of a database are independent: export and import process them on a few threads.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace panoptes::cinema {

/// Calls `fn(s)` for every stream s in [0, streams) on up to `threads` threads (0 = the hardware's;
/// at most one per stream and 64), each stream on one thread. After the first exception no new
/// stream is started; it is rethrown here once every thread has stopped.
template <class Fn>
void for_each_stream(std::int64_t streams, int threads, Fn fn) {
  std::atomic<std::int64_t> next{0};
  std::mutex mutex;
  std::exception_ptr error;
  auto work = [&] {
    for (std::int64_t s; (s = next++) < streams;) {
      {
        std::lock_guard lock(mutex);
        if (error) return;
      }
      try {
        fn(s);
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!error) error = std::current_exception();
        return;
      }
    }
  };
  const int n = std::max(1, std::min<int>(threads > 0 ? threads : int(std::thread::hardware_concurrency()),
                                          int(std::min<std::int64_t>(streams, 64))));
  std::vector<std::thread> pool;
  for (int i = 1; i < n; ++i) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace panoptes::cinema
