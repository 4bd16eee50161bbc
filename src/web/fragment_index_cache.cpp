#include "web/fragment_index_cache.hpp"

#include "core/error.hpp"
#include "web/database_json.hpp"
#include "web/mp4_fragments.hpp"

namespace panoptes::web {

namespace fs = std::filesystem;

FragmentIndexCache::FragmentIndexCache(std::size_t max_bytes) : max_bytes_(max_bytes) {}

std::shared_ptr<const std::string> FragmentIndexCache::json(const fs::path& movie,
                                                        const std::function<void(nlohmann::json&)>& extra) {
  return get(movie, extra).first;
}

int FragmentIndexCache::frame_count(const fs::path& movie) { return get(movie, {}).second; }

std::pair<std::shared_ptr<const std::string>, int> FragmentIndexCache::get(
    const fs::path& movie, const std::function<void(nlohmann::json&)>& extra) {
  std::error_code ec;
  const auto size = fs::file_size(movie, ec);
  if (ec) throw FileError(movie.string(), "cannot read: " + ec.message());
  const auto mtime = fs::last_write_time(movie, ec);
  if (ec) throw FileError(movie.string(), "cannot read: " + ec.message());
  const std::string key = movie.string();
  {
    std::lock_guard lock(mutex_);
    if (const auto it = by_path_.find(key); it != by_path_.end()) {
      if (it->second->size == size && it->second->mtime == mtime) {
        lru_.splice(lru_.begin(), lru_, it->second);
        ++hits_;
        return {it->second->json, it->second->frames};
      }
      bytes_ -= it->second->json->size();
      lru_.erase(it->second);
      by_path_.erase(it);
    }
    ++misses_;
  }
  // Built outside the lock: other streams are served meanwhile. Two requests for the same new movie
  // may both build it; the second insert just replaces the first.
  const FragmentIndex index = index_fragments(movie);
  nlohmann::json j = fragment_index_json(index);
  if (extra) extra(j);
  auto text = std::make_shared<const std::string>(j.dump());
  std::lock_guard lock(mutex_);
  insert(Entry{key, size, mtime, text, index.frame_count()});
  return {text, index.frame_count()};
}

void FragmentIndexCache::insert(Entry entry) {
  if (const auto it = by_path_.find(entry.path); it != by_path_.end()) {
    bytes_ -= it->second->json->size();
    lru_.erase(it->second);
    by_path_.erase(it);
  }
  bytes_ += entry.json->size();
  lru_.push_front(std::move(entry));
  by_path_[lru_.front().path] = lru_.begin();
  while (bytes_ > max_bytes_ && lru_.size() > 1) {
    bytes_ -= lru_.back().json->size();
    by_path_.erase(lru_.back().path);
    lru_.pop_back();
  }
}

std::shared_ptr<const std::string> FragmentIndexCache::json_keyed(const std::string& key, std::uint64_t version,
                                                                  const std::function<nlohmann::json()>& build) {
  // A key no path can take ("" is never a movie's path), with the version where a file's size goes.
  const std::string k = std::string(1, '\0') + key;
  {
    std::lock_guard lock(mutex_);
    if (const auto it = by_path_.find(k); it != by_path_.end() && it->second->size == version) {
      lru_.splice(lru_.begin(), lru_, it->second);
      ++hits_;
      return it->second->json;
    }
    ++misses_;
  }
  auto text = std::make_shared<const std::string>(build().dump());
  std::lock_guard lock(mutex_);
  insert(Entry{k, version, {}, text, 0});
  return text;
}

std::uint64_t FragmentIndexCache::hits() const {
  std::lock_guard lock(mutex_);
  return hits_;
}

std::uint64_t FragmentIndexCache::misses() const {
  std::lock_guard lock(mutex_);
  return misses_;
}

}  // namespace panoptes::web
