#pragma once
// The thread model of `panoptes serve`. cpp-httplib serves one connection on one thread for the
// connection's whole life (its keep-alive requests included), so a fixed pool of N threads is taken by
// any N connections, slow or idle ones too (issue 31: 16 slow sockets blocked every other request).
// Here a thread is started for each connection that finds none idle, up to a bound on connections
// served at once; threads left idle beyond the warm ones end after a while.
#include <httplib.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace panoptes::web {

/// An httplib task queue whose threads grow on demand from `warm` up to `max` and shrink back when
/// idle. A connection arriving while `max` are busy waits in the queue (accepted: it is not left in
/// the listen backlog) until one ends.
class ConnectionThreads : public httplib::TaskQueue {
 public:
  /// `warm` threads are started at once and kept; `max` >= warm bounds the threads at any time.
  ConnectionThreads(std::size_t warm, std::size_t max);
  ~ConnectionThreads() override;
  ConnectionThreads(const ConnectionThreads&) = delete;
  ConnectionThreads& operator=(const ConnectionThreads&) = delete;

  void enqueue(std::function<void()> fn) override;
  /// Runs what is queued, then joins every thread (httplib calls it once its listen loop ends).
  void shutdown() override;

  /// Threads alive now and the most alive at once so far (for tests and logs).
  std::size_t threads() const;
  std::size_t peak_threads() const;

 private:
  void work(bool warm);

  const std::size_t warm_, max_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;    // joined when they have ended (ended_) or at shutdown
  std::vector<std::thread::id> ended_;  // threads that left work() and await their join
  std::size_t alive_ = 0, idle_ = 0, peak_ = 0;
  bool shutdown_ = false;
};

}  // namespace panoptes::web
