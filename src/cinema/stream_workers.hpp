#pragma once
// Streams of a database are independent: export and import process them on a few threads.
#include <algorithm>
#include <cstdint>
#include <thread>

#include "core/parallel_for.hpp"

namespace panoptes::cinema {

/// Calls `fn(s)` for every stream s in [0, streams) on up to `threads` threads (0 = the hardware's;
/// at most one per stream and 64), each stream on one thread. After the first exception no new
/// stream is started; it is rethrown here once every thread has stopped.
template <class Fn>
void for_each_stream(std::int64_t streams, int threads, Fn fn) {
  const int n = std::max(1, std::min<int>(threads > 0 ? threads : int(std::thread::hardware_concurrency()),
                                          int(std::min<std::int64_t>(streams, 64))));
  parallel_for(streams, n, fn);
}

}  // namespace panoptes::cinema
