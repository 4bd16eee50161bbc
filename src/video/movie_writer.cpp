#include "video/movie_writer.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <sys/stat.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "video/ffmpeg_util.hpp"
#include "video/packet_checksum.hpp"

namespace panoptes::video {

namespace {

// An intra-only writer opens and frees an x264 encoder (several MB of buffers) for every frame.
// glibc serves blocks that large with mmap and returns them on free, so each frame paid for fresh
// pages: page faults and the kernel zeroing them. A fixed mmap threshold and a high trim threshold
// keep freed encoder memory in the heap for the next frame. Measured on the demo's 528x512 frames
// (2026-11-23, one thread, loaded machine): 7.9 ms of CPU per appended frame before, 2.6 ms after,
// movie bytes unchanged. Process-wide and once; the heap then keeps up to 256 MB free per arena.
void keep_freed_encoder_memory() {
#ifdef __GLIBC__
  static std::once_flag once;
  std::call_once(once, [] {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
  });
#endif
}

// Removes SEI NAL units (type 6) from an Annex B packet, in place. Each fresh x264 encoder puts its
// version-and-options SEI (~550 bytes) into its first packet; intra-only movies get a fresh encoder
// per frame, and the copy in every frame after the first is pure overhead (15 % of a 320x240 frame).
void strip_sei(AVPacket* pkt) {
  std::uint8_t* d = pkt->data;
  const int n = pkt->size;
  auto start_code = [&](int from) {
    for (int k = from; k + 2 < n; ++k)
      if (d[k] == 0 && d[k + 1] == 0 && d[k + 2] == 1) return k;
    return n;
  };
  int sc = start_code(0);
  if (sc > 1 || (sc == 1 && d[0] != 0)) return;  // not Annex B: leave it alone
  int out = 0;
  while (sc < n) {
    const int begin = sc > 0 && d[sc - 1] == 0 ? sc - 1 : sc;  // a 4-byte start code's zero_byte
    const int next = start_code(sc + 3);
    const int end = next < n && d[next - 1] == 0 ? next - 1 : next;
    const bool sei = sc + 3 < n && (d[sc + 3] & 0x1f) == 6;
    if (!sei) {
      std::memmove(d + out, d + begin, std::size_t(end - begin));
      out += end - begin;
    }
    sc = next;
  }
  if (out > 0) pkt->size = out;
}

}  // namespace

struct MovieWriter::Impl {
  std::string path;
  int fd = -1;             // with a caller's descriptor: written through a custom AVIOContext
  std::int64_t fd_pos = 0;
  int width = 0, height = 0, padded_width = 0, padded_height = 0;
  VideoSettings settings;

  AVFormatContext* fmt = nullptr;
  AVStream* stream = nullptr;
  AVCodecContext* enc = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* pkt = nullptr;
  SwsContext* sws_rgb = nullptr;
  SwsContext* sws_rgba = nullptr;
  std::vector<std::uint8_t> padded;  // odd sizes only: the frame with its last column/row repeated

  std::int64_t frames_in = 0;    // frames sent to the encoder
  std::int64_t packets_out = 0;  // packets handed to the muxer
  bool open = false;
  bool failed = false;  // a write failed: the file is no longer extended
  // Intra-only movies (gop 1) need no encoder state between frames, so the encoder, the YUV frame and
  // the converter exist only during append(): an open writer then holds little more than the muxer.
  // (An x264 encoder at 920x896 holds ~15-25 MB of reference, look-ahead and scratch frames.)
  bool transient = false;

  ~Impl() { release(); }

  // Frees the per-frame machinery (encoder, frame, converters); the muxer stays.
  void release_encoder() {
    avcodec_free_context(&enc);
    av_frame_free(&frame);
    sws_freeContext(sws_rgb);
    sws_freeContext(sws_rgba);
    sws_rgb = sws_rgba = nullptr;
  }

  void release() {
    release_encoder();
    if (fmt) {
      if (fmt->pb && fd >= 0) {
        avio_flush(fmt->pb);
        av_freep(&fmt->pb->buffer);
        avio_context_free(&fmt->pb);
      } else if (fmt->pb) {
        avio_closep(&fmt->pb);
      }
      avformat_free_context(fmt);
      fmt = nullptr;
    }
    av_packet_free(&pkt);
    if (fd >= 0) ::close(fd);
    fd = -1;
    open = false;
  }

  static int fd_write(void* opaque, std::uint8_t* buf, int n) {
    auto* m = static_cast<Impl*>(opaque);
    int done = 0;
    while (done < n) {
      const ssize_t w = ::pwrite(m->fd, buf + done, std::size_t(n - done), m->fd_pos);
      if (w < 0 && errno == EINTR) continue;
      if (w < 0) return AVERROR(errno);
      done += int(w);
      m->fd_pos += w;
    }
    return n;
  }

  static std::int64_t fd_seek(void* opaque, std::int64_t offset, int whence) {
    auto* m = static_cast<Impl*>(opaque);
    switch (whence & ~AVSEEK_FORCE) {
      case AVSEEK_SIZE: {
        struct stat st{};
        return ::fstat(m->fd, &st) == 0 ? std::int64_t(st.st_size) : AVERROR(errno);
      }
      case SEEK_SET: m->fd_pos = offset; break;
      case SEEK_CUR: m->fd_pos += offset; break;
      case SEEK_END: {
        struct stat st{};
        if (::fstat(m->fd, &st) != 0) return AVERROR(errno);
        m->fd_pos = st.st_size + offset;
        break;
      }
      default: return AVERROR(EINVAL);
    }
    return m->fd_pos;
  }

  [[noreturn]] void fail_write(const std::string& what, int err) {
    failed = true;
    throw FileError(path, what + ": " + av_error_string(err));
  }

  void check_io(const std::string& what) {
    if (fmt->pb && fmt->pb->error < 0) fail_write(what, fmt->pb->error);
  }

  void open_encoder() {
    const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
    if (!codec) throw Error("movie " + path + ": FFmpeg has no libx264 encoder");
    avcodec_free_context(&enc);
    enc = avcodec_alloc_context3(codec);
    if (!enc) throw Error("movie " + path + ": out of memory");
    enc->width = padded_width;
    enc->height = padded_height;
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
    if (fmt->oformat->flags & AVFMT_GLOBALHEADER) enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;

    AVDictionary* opts = nullptr;
    av_dict_set(&opts, "preset", settings.preset.c_str(), 0);
    // Intra-only movies get a fresh encoder per frame (see `transient`), and a fresh x264 in CRF mode
    // has no rate history: it spends about twice the bits on its first frame. A constant quantizer
    // equal to the CRF value gives every frame the quality a running CRF encoder settles at
    // (measured: docs/formats.md), deterministically and independent of the frames before.
    av_dict_set(&opts, settings.gop == 1 ? "qp" : "crf", std::to_string(settings.crf).c_str(), 0);
    // rc-lookahead=0 / sync-lookahead=0: no look-ahead queue (it both delays frames and costs a
    // full-size frame of memory per entry; it also turns off mb-tree). scenecut=0 keeps keyframes at
    // exact multiples of the GOP, so the worst-case random-access cost is known.
    av_dict_set(&opts, "x264-params", "rc-lookahead=0:sync-lookahead=0:scenecut=0:bframes=0", 0);
    int ret = avcodec_open2(enc, codec, &opts);
    av_dict_free(&opts);
    if (ret < 0) throw Error("movie " + path + ": cannot open the libx264 encoder: " + av_error_string(ret));
    if (stream) {
      // A re-opened encoder must describe its stream exactly as the header already written does.
      const AVCodecParameters* par = stream->codecpar;
      if (par->extradata_size != enc->extradata_size ||
          std::memcmp(par->extradata, enc->extradata, std::size_t(enc->extradata_size)) != 0)
        throw Error("movie " + path + ": the re-opened encoder wrote different stream headers");
    }

    frame = av_frame_alloc();
    if (!frame) throw Error("movie " + path + ": out of memory");
    frame->format = AV_PIX_FMT_YUV420P;
    frame->width = padded_width;
    frame->height = padded_height;
    frame->color_range = AVCOL_RANGE_MPEG;
    frame->colorspace = AVCOL_SPC_SMPTE170M;
    ret = av_frame_get_buffer(frame, 0);
    if (ret < 0) throw Error("movie " + path + ": out of memory for a frame");
  }

  void start() {
    int ret = avformat_alloc_output_context2(&fmt, nullptr, "mp4", path.c_str());
    if (ret < 0 || !fmt) throw Error("movie " + path + ": cannot allocate the MP4 muxer: " + av_error_string(ret));
    if (fd >= 0) {
      constexpr int kIoBuffer = 1 << 16;
      auto* buf = static_cast<std::uint8_t*>(av_malloc(kIoBuffer));
      fmt->pb = buf ? avio_alloc_context(buf, kIoBuffer, 1, this, nullptr, &fd_write, &fd_seek) : nullptr;
      if (!fmt->pb) {
        av_free(buf);
        throw Error("movie " + path + ": out of memory");
      }
      fmt->flags |= AVFMT_FLAG_CUSTOM_IO;
    } else {
      ret = avio_open(&fmt->pb, path.c_str(), AVIO_FLAG_WRITE);
      if (ret < 0) throw FileError(path, "cannot create the movie: " + av_error_string(ret));
    }
    open_encoder();
    stream = avformat_new_stream(fmt, nullptr);
    if (!stream) throw Error("movie " + path + ": out of memory");
    stream->time_base = enc->time_base;
    stream->avg_frame_rate = enc->framerate;
    ret = avcodec_parameters_from_context(stream->codecpar, enc);
    if (ret < 0) throw Error("movie " + path + ": " + av_error_string(ret));

    AVDictionary* opts = nullptr;
    // Fragmented MP4: the moov (without samples) is written first and every fragment (moof+mdat) is
    // self-describing, so the file is a valid movie up to its last complete fragment at any moment.
    av_dict_set(&opts, "movflags", "frag_keyframe+empty_moov+default_base_moof", 0);
    ret = avformat_write_header(fmt, &opts);
    av_dict_free(&opts);
    if (ret < 0) fail_write("cannot write the movie header", ret);
    avio_flush(fmt->pb);
    check_io("cannot write the movie header");

    pkt = av_packet_alloc();
    if (!pkt) throw Error("movie " + path + ": out of memory");
    transient = settings.gop == 1;
    if (transient) {
      release_encoder();
      keep_freed_encoder_memory();
    }
    open = true;
  }

  // Hands every packet the encoder has ready to the muxer.
  void drain_packets() {
    for (;;) {
      int ret = avcodec_receive_packet(enc, pkt);
      if (ret == AVERROR(EAGAIN) || ret == AVERROR_EOF) return;
      if (ret < 0) throw Error("movie " + path + ": encoding failed: " + av_error_string(ret));
      if (pkt->duration <= 0) pkt->duration = 1;  // one frame; the muxer needs it for the last sample
      if (transient && packets_out > 0) {
        ret = av_packet_make_writable(pkt);
        if (ret < 0) throw Error("movie " + path + ": out of memory");
        strip_sei(pkt);
      }
      // Every packet carries the CRC-32 of its pictures (packet_checksum.hpp): readers then tell a
      // damaged picture from a good one even when the damage decodes without a decoder error.
      if (av_packet_make_writable(pkt) < 0)
        throw Error("movie " + path + ": out of memory");
      append_packet_checksum(pkt);
      av_packet_rescale_ts(pkt, enc->time_base, stream->time_base);
      pkt->stream_index = stream->index;
      ret = av_write_frame(fmt, pkt);
      av_packet_unref(pkt);
      if (ret < 0) fail_write("cannot write frame " + std::to_string(packets_out), ret);
      ++packets_out;
      check_io("cannot write frame " + std::to_string(packets_out - 1));
    }
  }

  // Drains the encoder's delayed frames (none with our settings) and frees it.
  void finish_encoder() {
    if (!enc) return;
    int ret = avcodec_send_frame(enc, nullptr);
    if (ret < 0 && ret != AVERROR_EOF) throw Error("movie " + path + ": " + av_error_string(ret));
    drain_packets();
    release_encoder();
  }

  SwsContext* converter(int channels) {
    SwsContext*& ctx = channels == 4 ? sws_rgba : sws_rgb;
    if (!ctx) {
      // Full-resolution chroma input (FULL_CHR_H_INP) and accurate rounding: sharp coloured edges of
      // rendered images survive 4:2:0 better; the cost is small next to the encoder.
      ctx = sws_getContext(padded_width, padded_height, channels == 4 ? AV_PIX_FMT_RGBA : AV_PIX_FMT_RGB24,
                           padded_width, padded_height, AV_PIX_FMT_YUV420P,
                           SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INP, nullptr, nullptr, nullptr);
      if (!ctx) throw Error("movie " + path + ": cannot create the RGB to YUV converter");
      // BT.601, full-range RGB in, limited-range YUV out: what the stream's colour tags say.
      const int* coeffs = sws_getCoefficients(SWS_CS_ITU601);
      sws_setColorspaceDetails(ctx, coeffs, 1, coeffs, 0, 0, 1 << 16, 1 << 16);
    }
    return ctx;
  }
};

MovieWriter::MovieWriter(const std::string& path, int width, int height, const VideoSettings& settings)
    : MovieWriter(-1, path, width, height, settings) {}

MovieWriter::MovieWriter(int fd, const std::string& path, int width, int height, const VideoSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  impl_->fd = fd;  // owned from here on, also if a check below throws
  settings.validate();
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw Error("movie " + path + ": frame size " + std::to_string(width) + "x" + std::to_string(height) +
                " is outside 1x1..16384x16384");
  quiet_ffmpeg_logs();
  impl_->path = path;
  impl_->width = width;
  impl_->height = height;
  impl_->padded_width = width + (width & 1);
  impl_->padded_height = height + (height & 1);
  impl_->settings = settings;
  impl_->start();
}

MovieWriter::~MovieWriter() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; the error was the caller's to see by calling close().
  }
}

void MovieWriter::append(const Image& image) {
  Impl& m = *impl_;
  if (!m.open) throw Error("movie " + m.path + ": append after close");
  if (image.channels != 3 && image.channels != 4)
    throw Error("movie " + m.path + ": frame has " + std::to_string(image.channels) +
                " channels, expected 3 (RGB) or 4 (RGBA)");
  if (image.width != m.width || image.height != m.height)
    throw Error("movie " + m.path + ": frame is " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + ", expected " + std::to_string(m.width) + "x" +
                std::to_string(m.height));
  if (image.pixels.size() < image.stride() * std::size_t(image.height))
    throw Error("movie " + m.path + ": frame pixel buffer is smaller than its size says");
  if (m.failed) throw FileError(m.path, "an earlier write failed; the movie ends at its last flushed frame");
  if (!m.enc) m.open_encoder();

  const std::uint8_t* src = image.pixels.data();
  int src_stride = int(image.stride());
  if (m.padded_width != m.width || m.padded_height != m.height) {
    const int c = image.channels;
    const std::size_t pstride = std::size_t(m.padded_width) * c;
    m.padded.resize(pstride * m.padded_height);
    for (int y = 0; y < m.padded_height; ++y) {
      const std::uint8_t* in = image.row(std::min(y, m.height - 1));
      std::uint8_t* out = m.padded.data() + y * pstride;
      std::memcpy(out, in, image.stride());
      if (m.padded_width != m.width) std::memcpy(out + image.stride(), in + image.stride() - c, c);
    }
    src = m.padded.data();
    src_stride = int(pstride);
  }

  int ret = av_frame_make_writable(m.frame);
  if (ret < 0) throw Error("movie " + m.path + ": out of memory for a frame");
  const std::uint8_t* planes[1] = {src};
  sws_scale(m.converter(image.channels), planes, &src_stride, 0, m.padded_height, m.frame->data,
            m.frame->linesize);
  m.frame->pts = m.frames_in;
  ret = avcodec_send_frame(m.enc, m.frame);
  if (ret < 0) throw Error("movie " + m.path + ": encoder refused frame " + std::to_string(m.frames_in) + ": " +
                           av_error_string(ret));
  ++m.frames_in;
  m.drain_packets();
  if (m.transient) {
    if (m.packets_out == m.frames_in)
      m.release_encoder();  // nothing pending: the next frame is a keyframe from a fresh encoder
    else
      m.finish_encoder();
  }
}

void MovieWriter::flush() {
  Impl& m = *impl_;
  if (!m.open) return;
  if (m.failed) throw FileError(m.path, "an earlier write failed; the movie ends at its last flushed frame");
  // With the settings of open_encoder() x264 returns each packet at once; should a configuration
  // ever hold frames back, drain it (a fresh encoder starts with a keyframe at the next append).
  if (m.packets_out < m.frames_in) m.finish_encoder();
  if (m.packets_out < m.frames_in)
    throw Error("movie " + m.path + ": the encoder kept " + std::to_string(m.frames_in - m.packets_out) +
                " frames after draining");
  // A null packet makes the MP4 muxer close the current fragment (moof+mdat) now.
  int ret = av_write_frame(m.fmt, nullptr);
  if (ret < 0) m.fail_write("cannot write a fragment", ret);
  avio_flush(m.fmt->pb);
  m.check_io("cannot write a fragment");
}

void MovieWriter::close() {
  Impl& m = *impl_;
  if (!m.open) return;
  try {
    if (!m.failed) {
      m.finish_encoder();
      int ret = av_write_trailer(m.fmt);
      if (ret < 0) m.fail_write("cannot finish the movie", ret);
      avio_flush(m.fmt->pb);
      m.check_io("cannot finish the movie");
      if (m.fd >= 0) {
        // Custom I/O on the store's descriptor: everything is written (flushed above); release()
        // frees the context and closes the descriptor.
      } else {
        ret = avio_closep(&m.fmt->pb);
        if (ret < 0) m.fail_write("cannot close the movie", ret);
      }
    }
  } catch (...) {
    m.release();
    throw;
  }
  m.release();
}

int MovieWriter::frames_written() const { return int(impl_->frames_in); }
int MovieWriter::width() const { return impl_->width; }
int MovieWriter::height() const { return impl_->height; }
int MovieWriter::padded_width() const { return impl_->padded_width; }
int MovieWriter::padded_height() const { return impl_->padded_height; }
const std::string& MovieWriter::path() const { return impl_->path; }

}  // namespace panoptes::video
