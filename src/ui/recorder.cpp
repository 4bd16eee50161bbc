#include "ui/recorder.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include "core/error.hpp"

namespace panoptes::ui {

Recorder::~Recorder() {
  try {
    stop();
  } catch (...) {
  }
}

void Recorder::start(const std::filesystem::path& path, int width, int height, double fps, double now) {
  video::VideoSettings settings;
  settings.fps = fps;
  settings.crf = 20;
  settings.gop = std::max(1, int(std::lround(fps)));
  writer_ = std::make_unique<video::MovieWriter>(path.string(), width, height, settings);
  path_ = path.string();
  width_ = width;
  height_ = height;
  period_ = 1.0 / fps;
  start_ = now;
  queued_ = 0;
  stopping_ = false;
  error_.clear();
  encoder_ = std::thread([this] { encode_loop(); });
}

void Recorder::add(Image picture, double now) {
  const std::int64_t repeat = std::max<std::int64_t>(1, slots_until(now) - queued_);
  push({std::move(picture), repeat});
}

int Recorder::stop(double now) {
  if (!writer_) return 0;
  // Frames whose moment lies before `now`: ceil((now - start) / period), less a hair of rounding.
  const std::int64_t held = now >= start_ ? std::int64_t(std::ceil((now - start_) / period_ - 1e-6)) - queued_ : 0;
  {
    std::lock_guard lock(mutex_);
    if (held > 0 && queued_ > 0 && error_.empty()) {
      queue_.push_back({Image(), held});  // an empty picture repeats the previous one
      queued_ += held;
    }
    stopping_ = true;
  }
  work_.notify_one();
  encoder_.join();
  auto w = std::move(writer_);
  const int n = w->frames_written();
  std::string err;
  {
    std::lock_guard lock(mutex_);
    err = error_;
    queue_.clear();
  }
  if (!err.empty()) throw Error(err);
  w->close();
  return n;
}

void Recorder::push(Queued q) {
  std::unique_lock lock(mutex_);
  space_.wait(lock, [&] { return queue_.size() < kMaxQueued || !error_.empty(); });
  if (!error_.empty()) throw Error(error_);
  queued_ += q.repeat;
  queue_.push_back(std::move(q));
  work_.notify_one();
}

void Recorder::encode_loop() {
  Image last;
  for (;;) {
    Queued q;
    {
      std::unique_lock lock(mutex_);
      work_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) return;  // stopping and drained
      q = std::move(queue_.front());
      queue_.pop_front();
    }
    space_.notify_one();
    try {
      if (q.picture.width > 0) last = std::move(q.picture);
      for (std::int64_t i = 0; i < q.repeat && last.width > 0; ++i) writer_->append(last);
    } catch (const std::exception& ex) {
      std::lock_guard lock(mutex_);
      error_ = std::string("recording ") + path_ + ": " + ex.what();
      queue_.clear();
      space_.notify_all();
      return;
    }
  }
}

}  // namespace panoptes::ui
