#pragma once
// A bounded pool of open MovieReaders (LRU). A reader is lent to one thread at a time (MovieReader is
// not thread-safe); the total number of open readers (lent + idle) never exceeds the capacity.
#include <condition_variable>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "store/database.hpp"
#include "video/movie_reader.hpp"

namespace panoptes::player {

/// LRU pool of readers over one database. Thread-safe.
class ReaderPool {
 public:
  /// capacity ≥ 1. The database must outlive the pool.
  ReaderPool(const store::Database& database, int capacity);

  /// A reader of stream (camera, task), exclusively the caller's until release()/discard(): an idle
  /// one if the pool has it, else a newly opened one (closing the least recently used idle reader when
  /// the pool is full; waiting if every reader is lent out). Throws what Database::stream throws.
  std::unique_ptr<video::MovieReader> acquire(int camera, int task);
  /// Returns a reader to the pool (it becomes the most recently used idle reader).
  void release(int camera, int task, std::unique_ptr<video::MovieReader> reader);
  /// Closes a lent reader instead of returning it (after a decode error left it in a doubtful state).
  void discard(std::unique_ptr<video::MovieReader> reader);

  /// Closes every idle reader and marks the lent ones stale (they are closed when returned). For a
  /// database that grew: a reader indexes the movie's packets when it is opened.
  void invalidate();

  int capacity() const { return capacity_; }
  int open() const;               ///< readers open now (idle + lent)
  std::int64_t opened() const;    ///< readers opened since construction
  std::int64_t evicted() const;   ///< idle readers closed to respect the bound

 private:
  struct Idle {
    std::int64_t stream;
    std::unique_ptr<video::MovieReader> reader;
  };
  const store::Database& database_;
  const int capacity_;
  mutable std::mutex mutex_;
  std::condition_variable returned_;
  std::list<Idle> idle_;  // front = most recently used
  std::unordered_map<const video::MovieReader*, std::uint64_t> lent_epoch_;
  std::uint64_t epoch_ = 0;
  int open_ = 0;
  std::int64_t opened_ = 0, evicted_ = 0;
};

}  // namespace panoptes::player
