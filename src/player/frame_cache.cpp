#include "player/frame_cache.hpp"

namespace panoptes::player {

std::size_t frame_bytes(const video::YuvFrame& frame) {
  return frame.y.capacity() + frame.u.capacity() + frame.v.capacity() + sizeof(video::YuvFrame) + 64;
}

FrameCache::FrameCache(std::size_t capacity_bytes) : capacity_(capacity_bytes) {}

FrameCache::Claim FrameCache::claim(const FrameKey& key, std::shared_ptr<const video::YuvFrame>& out) {
  std::lock_guard lock(mutex_);
  if (auto it = entries_.find(key); it != entries_.end()) {
    lru_.splice(lru_.begin(), lru_, it->second.lru);
    out = it->second.frame;
    return Claim::cached;
  }
  if (in_flight_.count(key)) return Claim::in_flight;
  in_flight_.insert(key);
  return Claim::claimed;
}

void FrameCache::insert_locked(const FrameKey& key, std::shared_ptr<const video::YuvFrame> frame,
                               std::vector<std::shared_ptr<const video::YuvFrame>>& dropped) {
  const std::size_t size = frame_bytes(*frame);
  if (size > capacity_ || entries_.count(key)) return;
  while (bytes_ + size > capacity_ && !lru_.empty()) {
    const FrameKey victim = lru_.back();
    auto it = entries_.find(victim);
    bytes_ -= it->second.bytes;
    dropped.push_back(std::move(it->second.frame));
    entries_.erase(it);
    lru_.pop_back();
    ++evictions_;
  }
  lru_.push_front(key);
  entries_.emplace(key, Entry{std::move(frame), size, lru_.begin()});
  bytes_ += size;
}

void FrameCache::finish(const FrameKey& key, std::shared_ptr<const video::YuvFrame> frame) {
  std::vector<std::shared_ptr<const video::YuvFrame>> dropped;
  {
    std::lock_guard lock(mutex_);
    in_flight_.erase(key);
    if (frame) insert_locked(key, std::move(frame), dropped);
  }
  done_.notify_all();
  // `dropped` (and a frame too big to cache) are freed here, outside the lock: freeing megabytes of
  // planes means munmap system calls, which must not hold up the display thread's lookups.
}

std::shared_ptr<const video::YuvFrame> FrameCache::wait(const FrameKey& key) {
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return in_flight_.count(key) == 0; });
  if (auto it = entries_.find(key); it != entries_.end()) {
    lru_.splice(lru_.begin(), lru_, it->second.lru);
    return it->second.frame;
  }
  return nullptr;
}

bool FrameCache::contains(const FrameKey& key) const {
  std::lock_guard lock(mutex_);
  return entries_.count(key) != 0;
}

std::size_t FrameCache::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}

std::size_t FrameCache::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

std::int64_t FrameCache::evictions() const {
  std::lock_guard lock(mutex_);
  return evictions_;
}

}  // namespace panoptes::player
