#include "video/intra_encoder_pool.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
}

#include <cstring>
#include <map>
#include <tuple>

#include "core/error.hpp"
#include "video/ffmpeg_util.hpp"

namespace panoptes::video {

namespace {

using PoolKey = std::tuple<int, int, int, std::string, int, double>;  // width, height, crf, preset, threads, fps

std::mutex registry_mutex;
std::map<PoolKey, std::weak_ptr<IntraEncoderPool>>& registry() {
  static std::map<PoolKey, std::weak_ptr<IntraEncoderPool>> pools;
  return pools;
}

}  // namespace

std::shared_ptr<IntraEncoderPool> IntraEncoderPool::shared(int width, int height, const VideoSettings& settings,
                                                           const std::string& path) {
  if (settings.gop != 1) throw Error("movie " + path + ": shared encoders are for intra-only movies (gop 1)");
  const PoolKey key{width, height, settings.crf, settings.preset, settings.threads, settings.fps};
  std::lock_guard lock(registry_mutex);
  auto& pools = registry();
  if (auto pool = pools[key].lock()) return pool;
  // Forget pools no writer holds any more, so the map does not grow with every size ever used.
  std::erase_if(pools, [](const auto& entry) { return entry.second.expired(); });
  auto pool = std::make_shared<IntraEncoderPool>(width, height, settings, path);
  pools[key] = pool;
  return pool;
}

IntraEncoderPool::IntraEncoderPool(int width, int height, const VideoSettings& settings, const std::string& path)
    : width_(width), height_(height), settings_(settings) {
  auto first = open(path);
  parameters_ = avcodec_parameters_alloc();
  if (!parameters_ || avcodec_parameters_from_context(parameters_, first->context) < 0) {
    avcodec_parameters_free(&parameters_);
    throw Error("movie " + path + ": out of memory");
  }
  idle_.push_back(std::move(first));
}

IntraEncoderPool::~IntraEncoderPool() { avcodec_parameters_free(&parameters_); }

std::unique_ptr<H264Encoder> IntraEncoderPool::open(const std::string& path) {
  auto encoder = std::make_unique<H264Encoder>(width_, height_, settings_, true, path);
  if (parameters_) {
    // Frames of one movie may come from any encoder of the pool: all must write the same headers.
    const AVCodecContext* c = encoder->context;
    if (parameters_->extradata_size != c->extradata_size ||
        std::memcmp(parameters_->extradata, c->extradata, std::size_t(c->extradata_size)) != 0)
      throw Error("movie " + path + ": a second x264 encoder with the same settings wrote different stream headers");
  }
  std::lock_guard lock(mutex_);
  ++opened_;
  return encoder;
}

std::unique_ptr<H264Encoder> IntraEncoderPool::acquire(const std::string& path) {
  {
    std::lock_guard lock(mutex_);
    if (!idle_.empty()) {
      auto encoder = std::move(idle_.back());
      idle_.pop_back();
      return encoder;
    }
  }
  return open(path);  // outside the lock: opening x264 takes milliseconds
}

void IntraEncoderPool::release(std::unique_ptr<H264Encoder> encoder) {
  if (!encoder) return;
  std::lock_guard lock(mutex_);
  idle_.push_back(std::move(encoder));
}

void IntraEncoderPool::remember_sei(const std::vector<std::uint8_t>& sei) {
  std::lock_guard lock(mutex_);
  if (sei_.empty()) sei_ = sei;
}

std::vector<std::uint8_t> IntraEncoderPool::sei() const {
  std::lock_guard lock(mutex_);
  return sei_;
}

int IntraEncoderPool::encoders_opened() const {
  std::lock_guard lock(mutex_);
  return opened_;
}

}  // namespace panoptes::video
