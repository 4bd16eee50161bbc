#include "web/connection_threads.hpp"

#include <algorithm>
#include <chrono>

namespace panoptes::web {

namespace {
// A thread beyond the warm ones that saw no connection for this long ends: a burst of clients leaves
// no hundreds of sleeping threads behind, and a steady load does not start one thread per connection.
constexpr auto kIdleEnd = std::chrono::seconds(10);
}  // namespace

ConnectionThreads::ConnectionThreads(std::size_t warm, std::size_t max)
    : warm_(std::max<std::size_t>(1, warm)), max_(std::max(max, std::max<std::size_t>(1, warm))) {
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < warm_; ++i) threads_.emplace_back([this] { work(true); });
  alive_ = peak_ = warm_;
}

ConnectionThreads::~ConnectionThreads() { shutdown(); }

void ConnectionThreads::enqueue(std::function<void()> fn) {
  std::lock_guard lock(mutex_);
  jobs_.push_back(std::move(fn));
  if (idle_ >= jobs_.size() || alive_ >= max_) {
    ready_.notify_one();
    return;
  }
  // Every idle thread is spoken for by a queued connection: start one more, after joining those that
  // ended (they have let go of the lock: join waits for their last instructions only).
  std::erase_if(threads_, [this](std::thread& t) {
    if (std::find(ended_.begin(), ended_.end(), t.get_id()) == ended_.end()) return false;
    t.join();
    return true;
  });
  ended_.clear();
  threads_.emplace_back([this] { work(false); });
  peak_ = std::max(peak_, ++alive_);
}

void ConnectionThreads::work(bool warm) {
  std::unique_lock lock(mutex_);
  for (;;) {
    ++idle_;
    const auto has_work = [this] { return !jobs_.empty() || shutdown_; };
    bool woke = true;
    if (warm)
      ready_.wait(lock, has_work);
    else
      woke = ready_.wait_for(lock, kIdleEnd, has_work);
    --idle_;
    if (!woke || jobs_.empty()) break;  // idle too long, or shut down with nothing left to serve
    auto fn = std::move(jobs_.front());
    jobs_.pop_front();
    lock.unlock();
    fn();
    fn = nullptr;  // release what the task holds before taking the lock again
    lock.lock();
  }
  --alive_;
  ended_.push_back(std::this_thread::get_id());
}

void ConnectionThreads::shutdown() {
  std::vector<std::thread> threads;
  {
    std::lock_guard lock(mutex_);
    shutdown_ = true;
    threads.swap(threads_);
  }
  ready_.notify_all();
  for (auto& t : threads)
    if (t.joinable()) t.join();
}

std::size_t ConnectionThreads::threads() const {
  std::lock_guard lock(mutex_);
  return alive_;
}

std::size_t ConnectionThreads::peak_threads() const {
  std::lock_guard lock(mutex_);
  return peak_;
}

}  // namespace panoptes::web
