#pragma once
// A thread-safe LRU cache of decoded frames with a memory cap, which also tracks frames being decoded
// right now ("in flight") so the display thread waits for a prefetch decode instead of repeating it.
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "video/movie_reader.hpp"

namespace panoptes::player {

/// Identifies one frame of one stream (stream = camera * task_count + task).
struct FrameKey {
  std::int64_t stream = 0;
  int frame = 0;
  bool operator==(const FrameKey&) const = default;
};

struct FrameKeyHash {
  std::size_t operator()(const FrameKey& k) const noexcept {
    return std::hash<std::uint64_t>()(std::uint64_t(k.stream) * 0x9E3779B97F4A7C15ull ^ std::uint64_t(k.frame));
  }
};

/// Bytes a frame occupies in the cache (planes plus bookkeeping).
std::size_t frame_bytes(const video::YuvFrame& frame);

/// LRU frame cache. Every method is thread-safe.
class FrameCache {
 public:
  explicit FrameCache(std::size_t capacity_bytes);

  /// Outcome of claim().
  enum class Claim {
    cached,     ///< `out` holds the frame
    claimed,    ///< the caller must decode it and call finish()
    in_flight,  ///< another thread is decoding it: call wait()
  };
  /// Looks key up (a hit refreshes its LRU position); if absent and not in flight, marks it in flight.
  Claim claim(const FrameKey& key, std::shared_ptr<const video::YuvFrame>& out);
  /// Ends a claim: stores frame (if non-null and it fits) and wakes waiters.
  void finish(const FrameKey& key, std::shared_ptr<const video::YuvFrame> frame);
  /// Waits until key is no longer in flight; returns the cached frame or null (decode failed/too big).
  std::shared_ptr<const video::YuvFrame> wait(const FrameKey& key);
  bool contains(const FrameKey& key) const;

  std::size_t bytes() const;
  std::size_t capacity() const { return capacity_; }
  std::size_t size() const;
  std::int64_t evictions() const;

 private:
  struct Entry {
    std::shared_ptr<const video::YuvFrame> frame;
    std::size_t bytes = 0;
    std::list<FrameKey>::iterator lru;
  };
  // Evicted frames are moved to `dropped` so their memory is freed after the lock is released.
  void insert_locked(const FrameKey& key, std::shared_ptr<const video::YuvFrame> frame,
                     std::vector<std::shared_ptr<const video::YuvFrame>>& dropped);

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable done_;
  std::list<FrameKey> lru_;  // front = most recently used
  std::unordered_map<FrameKey, Entry, FrameKeyHash> entries_;
  std::unordered_set<FrameKey, FrameKeyHash> in_flight_;
  std::size_t bytes_ = 0;
  std::int64_t evictions_ = 0;
};

}  // namespace panoptes::player
