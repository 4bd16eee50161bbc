#pragma once
// The fragment indexes `panoptes serve` hands out, kept per movie so that a player asking for the
// same stream again (every switch back, every page load) costs one stat() instead of reading every
// box header of the movie. An entry is valid while the file's size and modification time are those
// it was built from: a movie still being written grows, so its next request re-indexes it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>

#include <nlohmann/json.hpp>

namespace panoptes::web {

/// A thread-safe LRU of fragment indexes as JSON text, keyed by path and checked against size and
/// modification time, bounded by the bytes of JSON it holds.
class FragmentIndexCache {
 public:
  /// `max_bytes`: the JSON text kept at most (an index is ~30 bytes per fragment).
  explicit FragmentIndexCache(std::size_t max_bytes = std::size_t(64) << 20);

  /// The index of `movie` as JSON (web::fragment_index_json), from the cache when the file's size and
  /// mtime are unchanged, else built (index_fragments) and kept. Throws what index_fragments throws.
  /// `extra`, if given, adds to the JSON object before it is cached (e.g. the frames that fail their
  /// frame checks): it runs once per build of the entry, not per request.
  std::shared_ptr<const std::string> json(const std::filesystem::path& movie,
                                          const std::function<void(nlohmann::json&)>& extra = {});
  /// The frames in the complete fragments of `movie` (FragmentIndex::frame_count), from the same entry.
  int frame_count(const std::filesystem::path& movie);
  /// An index that is no file's (a stream of a packed database): the JSON kept under `key` while
  /// `version` is the one it was built for (serve: the opened manifest's generation, since a pack's
  /// index names new fragments only with a new checkpoint), else build() and kept in the same LRU.
  /// Throws what build throws (nothing is kept then).
  std::shared_ptr<const std::string> json_keyed(const std::string& key, std::uint64_t version,
                                                const std::function<nlohmann::json()>& build);

  /// Counters for tests and logs.
  std::uint64_t hits() const;
  std::uint64_t misses() const;

 private:
  struct Entry {
    std::string path;
    std::uintmax_t size = 0;
    std::filesystem::file_time_type mtime;
    std::shared_ptr<const std::string> json;
    int frames = 0;
  };
  void insert(Entry entry);  // under mutex_: replaces the key's entry, evicts beyond max_bytes_
  std::pair<std::shared_ptr<const std::string>, int> get(const std::filesystem::path& movie,
                                                         const std::function<void(nlohmann::json&)>& extra);
  mutable std::mutex mutex_;
  std::list<Entry> lru_;  // front = most recently used
  std::unordered_map<std::string, std::list<Entry>::iterator> by_path_;
  std::size_t bytes_ = 0, max_bytes_;
  std::uint64_t hits_ = 0, misses_ = 0;
};

}  // namespace panoptes::web
