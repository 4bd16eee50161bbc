#include "video/intra_packet_encoder.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
}

#include <algorithm>
#include <cstring>

#include "core/error.hpp"
#include "video/ffmpeg_util.hpp"
#include "video/fmp4_fragment.hpp"
#include "video/h264_encoder.hpp"
#include "video/intra_encoder_pool.hpp"

namespace panoptes::video {

IntraPacketEncoder::IntraPacketEncoder(int width, int height, const VideoSettings& settings, const std::string& name)
    : width_(width), height_(height), padded_width_(width + (width & 1)), padded_height_(height + (height & 1)),
      name_(name) {
  settings.validate();
  if (settings.gop != 1)
    throw Error(name + ": the packed layout encodes intra-only movies (gop 1); gop " + std::to_string(settings.gop) +
                " needs the files layout");
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw Error(name + ": frame size " + std::to_string(width) + "x" + std::to_string(height) +
                " is outside 1x1..16384x16384");
  quiet_ffmpeg_logs();
  pool_ = IntraEncoderPool::shared(padded_width_, padded_height_, settings, name);
  const AVCodecParameters* par = pool_->parameters();
  header_.assign(par->extradata, par->extradata + par->extradata_size);
  header_crc_ = parameter_sets_crc(header_.data(), int(header_.size()));
}

IntraPacketEncoder::~IntraPacketEncoder() = default;

std::size_t IntraPacketEncoder::encode(const Image& image, std::uint32_t index,
                                       const std::optional<MovieIdentity>& identity, bool bind,
                                       std::vector<std::uint8_t>& out) {
  if (image.channels != 3 && image.channels != 4)
    throw Error(name_ + ": frame has " + std::to_string(image.channels) + " channels, expected 3 (RGB) or 4 (RGBA)");
  if (image.width != width_ || image.height != height_)
    throw Error(name_ + ": frame is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                ", expected " + std::to_string(width_) + "x" + std::to_string(height_));
  if (image.pixels.size() < image.stride() * std::size_t(image.height))
    throw Error(name_ + ": frame pixel buffer is smaller than its size says");
  const std::uint8_t* src = image.pixels.data();
  int src_stride = int(image.stride());
  std::vector<std::uint8_t> padded;
  if (padded_width_ != width_ || padded_height_ != height_) {  // edge repeated, as MovieWriter pads
    const int c = image.channels;
    const std::size_t pstride = std::size_t(padded_width_) * c;
    padded.resize(pstride * padded_height_);
    for (int y = 0; y < padded_height_; ++y) {
      const std::uint8_t* in = image.row(std::min(y, height_ - 1));
      std::uint8_t* o = padded.data() + y * pstride;
      std::memcpy(o, in, image.stride());
      if (padded_width_ != width_) std::memcpy(o + image.stride(), in + image.stride() - c, c);
    }
    src = padded.data();
    src_stride = int(pstride);
  }
  AVPacket* pkt = av_packet_alloc();
  if (!pkt) throw Error(name_ + ": out of memory");
  struct PacketGuard {
    AVPacket*& p;
    ~PacketGuard() { av_packet_free(&p); }
  } guard{pkt};
  {
    auto e = pool_->acquire(name_);
    e->convert(src, src_stride, image.channels);
    e->frame->pts = e->frames_sent;
    int ret = avcodec_send_frame(e->context, e->frame);
    if (ret < 0) throw Error(name_ + ": encoder refused frame " + std::to_string(index) + ": " + av_error_string(ret));
    ++e->frames_sent;
    ret = avcodec_receive_packet(e->context, pkt);
    if (ret < 0)
      throw Error(name_ + ": the encoder gave no packet for frame " + std::to_string(index) + ": " + av_error_string(ret));
    pool_->release(std::move(e));
  }
  if (av_packet_make_writable(pkt) < 0) throw Error(name_ + ": out of memory");
  // As MovieWriter: x264's version SEI once per movie, in its first frame.
  std::vector<std::uint8_t> sei;
  remove_sei(pkt, &sei);
  if (!sei.empty()) pool_->remember_sei(sei);
  if (index == 0) prepend_nal_units(pkt, pool_->sei());
  FrameStamp stamp;
  if (identity) {
    stamp.movie = bind ? bind_parameter_sets(*identity, header_crc_) : *identity;
    stamp.frame = index;
  }
  append_packet_checksum(pkt, identity ? &stamp : nullptr);
  return annex_b_to_mp4(pkt->data, std::size_t(pkt->size), out);
}

}  // namespace panoptes::video
