#pragma once
// The window's recorder: what is shown, as an MP4 (run_window's R key).
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/image.hpp"
#include "video/movie_writer.hpp"

namespace panoptes::ui {

/// Recording "what is shown": the window's picture (without the HUD) sampled at the database's frame
/// rate into an MP4 of the window's size at the start of the recording. The movie lasts as long as
/// the recording did: movie frame i stands for the moment start + i / fps, and when the display draws
/// fewer pictures per second than that (a slow machine, a large window) each picture is repeated over
/// the frame periods it was shown for, and the last one until the recording stops. Encoding runs on
/// its own thread so the display keeps its frame rate; the display thread only reads the pixels back.
class Recorder {
 public:
  ~Recorder();
  bool active() const { return writer_ != nullptr; }
  const std::string& path() const { return path_; }

  void start(const std::filesystem::path& path, int width, int height, double fps, double now);
  /// True if a frame is due at `now` (the caller then reads the pixels and calls add()).
  bool due(double now) const { return writer_ && slots_until(now) > queued_; }
  bool size_matches(int width, int height) const { return width == width_ && height == height_; }
  /// Queues a picture for encoding, as every movie frame due by `now` not yet queued. Blocks only
  /// while kMaxQueued pictures wait (a display much faster than the encoder then slows to the
  /// encoder's pace rather than dropping recorded frames). Throws panoptes::Error if the encoder
  /// thread failed (e.g. disk full).
  void add(Image picture, double now);
  /// Holds the last picture until `now` (when given: the moment the user stopped), encodes what is
  /// queued, closes the movie; returns the number of frames written. Throws panoptes::Error /
  /// FileError if encoding or closing failed.
  int stop(double now = -1);

 private:
  static constexpr std::size_t kMaxQueued = 4;
  struct Queued {
    Image picture;  // empty: the previous picture again
    std::int64_t repeat = 1;
  };

  // Movie frames whose moment start + i * period is at or before `now` (with a hair of tolerance, so
  // a virtual clock ticking exactly once per period gives exactly one frame per tick).
  std::int64_t slots_until(double now) const { return std::int64_t(std::floor((now - start_) / period_ + 1e-6)) + 1; }

  void push(Queued q);

  void encode_loop();

  std::unique_ptr<video::MovieWriter> writer_;
  std::string path_;
  int width_ = 0, height_ = 0;
  double period_ = 1.0 / 30, start_ = 0;
  std::int64_t queued_ = 0;  // movie frames queued so far (display thread only)
  std::thread encoder_;
  std::mutex mutex_;
  std::condition_variable work_, space_;
  std::deque<Queued> queue_;
  bool stopping_ = false;
  std::string error_;
};

}  // namespace panoptes::ui
