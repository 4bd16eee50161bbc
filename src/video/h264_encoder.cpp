#include "video/h264_encoder.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <cstring>

#include "core/error.hpp"
#include "video/annex_b.hpp"
#include "video/ffmpeg_util.hpp"

namespace panoptes::video {

H264Encoder::H264Encoder(int width, int height, const VideoSettings& settings, bool global_header,
                         const std::string& path)
    : path_(path) {
  try {
    const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
    if (!codec) throw Error("movie " + path + ": FFmpeg has no libx264 encoder");
    context = avcodec_alloc_context3(codec);
    if (!context) throw Error("movie " + path + ": out of memory");
    AVCodecContext* enc = context;
    enc->width = width;
    enc->height = height;
    enc->pix_fmt = AV_PIX_FMT_YUV420P;
    const AVRational rate = av_d2q(settings.fps, 1 << 20);
    enc->framerate = rate;
    enc->time_base = av_inv_q(rate);
    enc->gop_size = settings.gop;
    enc->keyint_min = settings.gop;
    // No B-frames: every packet leaves the encoder as soon as its frame is sent (flush() has nothing
    // to drain), decode order is display order and random access decodes only what precedes the frame.
    enc->max_b_frames = 0;
    enc->thread_count = settings.threads;
    // Slice threads add no frame delay; frame threads would hold `threads` frames back.
    enc->thread_type = FF_THREAD_SLICE;
    enc->color_range = AVCOL_RANGE_MPEG;
    enc->colorspace = AVCOL_SPC_SMPTE170M;
    enc->color_primaries = AVCOL_PRI_SMPTE170M;
    enc->color_trc = AVCOL_TRC_SMPTE170M;
    if (global_header) enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;

    AVDictionary* opts = nullptr;
    av_dict_set(&opts, "preset", settings.preset.c_str(), 0);
    // Intra-only frames are independent of each other, and a CRF encoder would carry rate history
    // from one movie's frame into another's (a fresh one spends about twice the bits on its first
    // frame). A constant quantizer equal to the CRF value gives every frame the quality a running CRF
    // encoder settles at (measured: docs/formats.md), deterministically, whoever encoded the frames before.
    av_dict_set(&opts, settings.gop == 1 ? "qp" : "crf", std::to_string(settings.crf).c_str(), 0);
    // rc-lookahead=0 / sync-lookahead=0: no look-ahead queue (it both delays frames and costs a
    // full-size frame of memory per entry; it also turns off mb-tree). scenecut=0 keeps keyframes at
    // exact multiples of the GOP, so the worst-case random-access cost is known. force-cfr: x264
    // holds one frame back for variable-frame-rate input even without look-ahead (measured: the
    // first packet came out with the second frame), which made every flush() drain and reopen the
    // encoder; our frames are constant-rate anyway.
    av_dict_set(&opts, "x264-params", "rc-lookahead=0:sync-lookahead=0:scenecut=0:bframes=0:force-cfr=1", 0);
    int ret = avcodec_open2(enc, codec, &opts);
    av_dict_free(&opts);
    if (ret < 0) throw Error("movie " + path + ": cannot open the libx264 encoder: " + av_error_string(ret));

    frame = av_frame_alloc();
    if (!frame) throw Error("movie " + path + ": out of memory");
    frame->format = AV_PIX_FMT_YUV420P;
    frame->width = width;
    frame->height = height;
    frame->color_range = AVCOL_RANGE_MPEG;
    frame->colorspace = AVCOL_SPC_SMPTE170M;
    ret = av_frame_get_buffer(frame, 0);
    if (ret < 0) throw Error("movie " + path + ": out of memory for a frame");
  } catch (...) {
    avcodec_free_context(&context);
    av_frame_free(&frame);
    throw;
  }
}

H264Encoder::~H264Encoder() {
  avcodec_free_context(&context);
  av_frame_free(&frame);
  sws_freeContext(sws_rgb_);
  sws_freeContext(sws_rgba_);
}

void H264Encoder::convert(const std::uint8_t* pixels, int stride, int channels) {
  SwsContext*& ctx = channels == 4 ? sws_rgba_ : sws_rgb_;
  if (!ctx) {
    // Full-resolution chroma input (FULL_CHR_H_INP) and accurate rounding: sharp coloured edges of
    // rendered images survive 4:2:0 better; the cost is small next to the encoder.
    ctx = sws_getContext(frame->width, frame->height, channels == 4 ? AV_PIX_FMT_RGBA : AV_PIX_FMT_RGB24,
                         frame->width, frame->height, AV_PIX_FMT_YUV420P,
                         SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INP, nullptr, nullptr, nullptr);
    if (!ctx) throw Error("movie " + path_ + ": cannot create the RGB to YUV converter");
    // BT.601, full-range RGB in, limited-range YUV out: what the stream's colour tags say.
    const int* coeffs = sws_getCoefficients(SWS_CS_ITU601);
    sws_setColorspaceDetails(ctx, coeffs, 1, coeffs, 0, 0, 1 << 16, 1 << 16);
  }
  if (av_frame_make_writable(frame) < 0) throw Error("movie " + path_ + ": out of memory for a frame");
  const std::uint8_t* planes[1] = {pixels};
  sws_scale(ctx, planes, &stride, 0, frame->height, frame->data, frame->linesize);
}

void remove_sei(AVPacket* pkt, std::vector<std::uint8_t>* removed) {
  std::uint8_t* d = pkt->data;
  const int n = pkt->size;
  auto start_code = [&](int from) { return next_start_code(d, n, from); };
  int sc = start_code(0);
  if (!is_annex_b(d, sc)) return;  // leave it alone
  int out = 0;
  while (sc < n) {
    const int begin = sc > 0 && d[sc - 1] == 0 ? sc - 1 : sc;  // a 4-byte start code's zero_byte
    const int next = start_code(sc + 3);
    const int end = next < n && d[next - 1] == 0 ? next - 1 : next;
    const bool sei = sc + 3 < n && (d[sc + 3] & 0x1f) == 6;
    if (sei && removed) {
      removed->insert(removed->end(), {0, 0, 0, 1});
      removed->insert(removed->end(), d + sc + 3, d + end);
    }
    if (!sei) {
      std::memmove(d + out, d + begin, std::size_t(end - begin));
      out += end - begin;
    }
    sc = next;
  }
  if (out > 0) pkt->size = out;
}

void prepend_nal_units(AVPacket* pkt, const std::vector<std::uint8_t>& bytes) {
  if (bytes.empty()) return;
  const int old = pkt->size;
  if (av_grow_packet(pkt, int(bytes.size())) < 0) throw Error("out of memory for a packet");
  std::memmove(pkt->data + bytes.size(), pkt->data, std::size_t(old));
  std::memcpy(pkt->data, bytes.data(), bytes.size());
}

}  // namespace panoptes::video
