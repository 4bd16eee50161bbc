#include "player/reader_pool.hpp"

#include "core/error.hpp"

namespace panoptes::player {

ReaderPool::ReaderPool(const store::Database& database, int capacity) : database_(database), capacity_(capacity) {
  require(capacity >= 1, "reader pool capacity must be at least 1, got " + std::to_string(capacity));
}

std::unique_ptr<video::MovieReader> ReaderPool::acquire(int camera, int task) {
  const std::int64_t stream = std::int64_t(camera) * database_.task_count() + task;
  std::unique_ptr<video::MovieReader> victim;  // closed outside the lock (closing frees codec state)
  {
    std::unique_lock lock(mutex_);
    for (auto it = idle_.begin(); it != idle_.end(); ++it)
      if (it->stream == stream) {
        auto reader = std::move(it->reader);
        idle_.erase(it);
        lent_epoch_[reader.get()] = epoch_;
        return reader;
      }
    // Make room: the bound counts lent readers too, so when all are lent we wait for one back.
    returned_.wait(lock, [&] { return open_ < capacity_ || !idle_.empty(); });
    if (open_ >= capacity_) {
      victim = std::move(idle_.back().reader);
      idle_.pop_back();
      --open_;
      ++evicted_;
    }
    ++open_;  // reserved before the (slow) open so concurrent acquires respect the bound
  }
  victim.reset();
  try {
    auto reader = database_.stream(camera, task);
    std::lock_guard lock(mutex_);
    ++opened_;
    lent_epoch_[reader.get()] = epoch_;
    return reader;
  } catch (...) {
    {
      std::lock_guard lock(mutex_);
      --open_;
    }
    returned_.notify_one();
    throw;
  }
}

void ReaderPool::release(int camera, int task, std::unique_ptr<video::MovieReader> reader) {
  if (!reader) return;
  const std::int64_t stream = std::int64_t(camera) * database_.task_count() + task;
  {
    std::lock_guard lock(mutex_);
    const auto it = lent_epoch_.find(reader.get());
    const bool stale = it != lent_epoch_.end() && it->second != epoch_;
    if (it != lent_epoch_.end()) lent_epoch_.erase(it);
    if (stale) {
      --open_;
    } else {
      idle_.push_front(Idle{stream, std::move(reader)});
    }
  }
  reader.reset();  // a stale reader is closed outside the lock
  returned_.notify_one();
}

void ReaderPool::invalidate() {
  std::list<Idle> closing;
  {
    std::lock_guard lock(mutex_);
    ++epoch_;
    open_ -= int(idle_.size());
    closing.swap(idle_);
  }
  returned_.notify_all();
}

void ReaderPool::discard(std::unique_ptr<video::MovieReader> reader) {
  if (!reader) return;
  {
    std::lock_guard lock(mutex_);
    lent_epoch_.erase(reader.get());
  }
  reader.reset();
  {
    std::lock_guard lock(mutex_);
    --open_;
  }
  returned_.notify_one();
}

int ReaderPool::open() const {
  std::lock_guard lock(mutex_);
  return open_;
}
std::int64_t ReaderPool::opened() const {
  std::lock_guard lock(mutex_);
  return opened_;
}
std::int64_t ReaderPool::evicted() const {
  std::lock_guard lock(mutex_);
  return evicted_;
}

}  // namespace panoptes::player
