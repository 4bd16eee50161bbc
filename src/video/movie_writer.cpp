#include "video/movie_writer.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "video/annex_b.hpp"
#include "video/ffmpeg_util.hpp"
#include "video/h264_encoder.hpp"
#include "video/intra_encoder_pool.hpp"
#include "video/movie_reader.hpp"
#include "video/packet_checksum.hpp"

namespace panoptes::video {

struct MovieWriter::Impl {
  std::string path;
  int fd = -1;             // with a caller's descriptor: written through a custom AVIOContext
  std::int64_t fd_pos = 0;
  int width = 0, height = 0, padded_width = 0, padded_height = 0;
  VideoSettings settings;
  std::optional<MovieIdentity> identity;  // stamped on every frame when set
  bool bind = false;                      // fold the parameter sets' CRC into it (bind_parameter_sets)
  std::optional<MovieIdentity> stamped;   // what frames carry: identity, bound once the header is known

  AVFormatContext* fmt = nullptr;
  AVStream* stream = nullptr;
  AVPacket* pkt = nullptr;
  // gop > 1: the writer's own encoder, alive as long as the movie (P-frames need the previous ones).
  std::unique_ptr<H264Encoder> own;
  // gop 1 (intra-only): no encoder state between frames, so each append() borrows an encoder from the
  // pool shared by every movie of this size and settings, and an open writer holds little more than
  // its muxer. (An x264 encoder at 920x896 holds ~15-25 MB of reference, look-ahead and scratch frames.)
  std::shared_ptr<IntraEncoderPool> pool;
  AVRational enc_time_base{1, 30};
  std::vector<std::uint8_t> padded;  // odd sizes only: the frame with its last column/row repeated

  std::int64_t frames_in = 0;    // frames sent to the encoder
  std::int64_t packets_out = 0;  // packets handed to the muxer
  bool open = false;
  bool failed = false;  // a write failed: the file is no longer extended

  ~Impl() { release(); }

  void release() {
    own.reset();
    pool.reset();
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
    const bool global_header = fmt->oformat->flags & AVFMT_GLOBALHEADER;
    if (settings.gop == 1 && global_header) {
      pool = IntraEncoderPool::shared(padded_width, padded_height, settings, path);
    } else {
      own = std::make_unique<H264Encoder>(padded_width, padded_height, settings, global_header, path);
    }
    stream = avformat_new_stream(fmt, nullptr);
    if (!stream) throw Error("movie " + path + ": out of memory");
    const AVRational rate = av_d2q(settings.fps, 1 << 20);
    enc_time_base = av_inv_q(rate);
    stream->time_base = enc_time_base;
    stream->avg_frame_rate = rate;
    ret = pool ? avcodec_parameters_copy(stream->codecpar, pool->parameters())
               : avcodec_parameters_from_context(stream->codecpar, own->context);
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
    open = true;
  }

  // Moves every packet `enc` has ready to the muxer (gop > 1: the writer's own encoder).
  void drain_packets(AVCodecContext* enc) {
    for (;;) {
      int ret = avcodec_receive_packet(enc, pkt);
      if (ret == AVERROR(EAGAIN) || ret == AVERROR_EOF) return;
      if (ret < 0) throw Error("movie " + path + ": encoding failed: " + av_error_string(ret));
      if (av_packet_make_writable(pkt) < 0) throw Error("movie " + path + ": out of memory");
      mux_packet();
    }
  }

  // Writes `pkt` (a writable packet with the encoder's timestamps) into the movie.
  void mux_packet() {
    if (pkt->duration <= 0) pkt->duration = 1;  // one frame; the muxer needs it for the last sample
    // Every packet carries the CRC-32 of its pictures (packet_checksum.hpp): readers then tell a
    // damaged picture from a good one even when the damage decodes without a decoder error.
    // With an identity the message also says whose frame this is and where it belongs.
    FrameStamp stamp;
    if (identity) {
      if (!stamped) {
        const AVCodecParameters* par = stream->codecpar;
        stamped = bind ? bind_parameter_sets(*identity, parameter_sets_crc(par->extradata, par->extradata_size)) : *identity;
      }
      stamp.movie = *stamped;
      stamp.frame = std::uint32_t(pkt->pts != AV_NOPTS_VALUE && pkt->pts >= 0 ? pkt->pts : packets_out);  // encoder clock = frame index
    }
    append_packet_checksum(pkt, identity ? &stamp : nullptr);
    av_packet_rescale_ts(pkt, enc_time_base, stream->time_base);
    pkt->stream_index = stream->index;
    int ret = av_write_frame(fmt, pkt);
    av_packet_unref(pkt);
    if (ret < 0) fail_write("cannot write frame " + std::to_string(packets_out), ret);
    ++packets_out;
    check_io("cannot write frame " + std::to_string(packets_out - 1));
  }

  // gop 1: encodes the converted picture in `e` (borrowed from the pool) and writes its packet.
  void encode_intra(std::unique_ptr<H264Encoder> e) {
    e->frame->pts = e->frames_sent;  // the encoder's own clock; the movie's is set below
    int ret = avcodec_send_frame(e->context, e->frame);
    if (ret < 0) throw Error("movie " + path + ": encoder refused frame " + std::to_string(frames_in) + ": " +
                             av_error_string(ret));
    ++e->frames_sent;
    ret = avcodec_receive_packet(e->context, pkt);
    // The settings of H264Encoder hold no frame back; one that did would mix movies' frames.
    if (ret < 0) throw Error("movie " + path + ": the encoder gave no packet for frame " + std::to_string(frames_in) +
                             ": " + av_error_string(ret));
    pool->release(std::move(e));  // free for other threads while this one writes
    if (av_packet_make_writable(pkt) < 0) throw Error("movie " + path + ": out of memory");
    // x264's version SEI comes in the first packet of each encoder, i.e. of some movies: every movie
    // gets it once, in its first packet, and no later packet carries a copy.
    std::vector<std::uint8_t> sei;
    remove_sei(pkt, &sei);
    if (!sei.empty()) pool->remember_sei(sei);
    if (packets_out == 0) prepend_nal_units(pkt, pool->sei());
    pkt->pts = pkt->dts = frames_in;
    pkt->duration = 1;
    pkt->flags |= AV_PKT_FLAG_KEY;
    mux_packet();
  }

  // gop > 1, after flush() had to drain the encoder: a fresh one, which starts with a keyframe.
  void reopen_encoder() {
    own = std::make_unique<H264Encoder>(padded_width, padded_height, settings, true, path);
    // A re-opened encoder must describe its stream exactly as the header already written does.
    const AVCodecParameters* par = stream->codecpar;
    if (par->extradata_size != own->context->extradata_size ||
        std::memcmp(par->extradata, own->context->extradata, std::size_t(par->extradata_size)) != 0)
      throw Error("movie " + path + ": the re-opened encoder wrote different stream headers");
  }

  // gop > 1: drains the encoder's delayed frames (none with our settings); it cannot take more.
  void finish_encoder() {
    if (!own) return;
    int ret = avcodec_send_frame(own->context, nullptr);
    if (ret < 0 && ret != AVERROR_EOF) throw Error("movie " + path + ": " + av_error_string(ret));
    drain_packets(own->context);
    own.reset();
  }
};

MovieWriter::MovieWriter(const std::string& path, int width, int height, const VideoSettings& settings)
    : MovieWriter(-1, path, width, height, settings) {}

MovieWriter::MovieWriter(int fd, const std::string& path, int width, int height, const VideoSettings& settings,
                         const std::optional<MovieIdentity>& identity, bool bind_parameter_sets)
    : impl_(std::make_unique<Impl>()) {
  impl_->fd = fd;  // owned from here on, also if a check below throws
  impl_->identity = identity;
  impl_->bind = bind_parameter_sets;
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
  if (!m.pool && !m.own) m.reopen_encoder();

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

  if (m.pool) {
    auto encoder = m.pool->acquire(m.path);
    encoder->convert(src, src_stride, image.channels);
    m.encode_intra(std::move(encoder));
    ++m.frames_in;
    return;
  }
  m.own->convert(src, src_stride, image.channels);
  m.own->frame->pts = m.frames_in;
  const int ret = avcodec_send_frame(m.own->context, m.own->frame);
  if (ret < 0) throw Error("movie " + m.path + ": encoder refused frame " + std::to_string(m.frames_in) + ": " +
                           av_error_string(ret));
  ++m.frames_in;
  m.drain_packets(m.own->context);
}

namespace {

// The NAL units (SPS, PPS) of an H.264 stream header, whether it is an avcC record (as an MP4 file
// stores it) or Annex B (as libx264 hands it to the muxer): the same stream has the same units.
std::vector<std::vector<std::uint8_t>> header_units(const std::uint8_t* d, int n) {
  std::vector<std::vector<std::uint8_t>> units;
  if (n >= 7 && d[0] == 1) {
    int at = 5;
    for (int kind = 0; kind < 2 && at < n; ++kind) {
      const int count = kind == 0 ? d[at] & 0x1f : d[at];
      ++at;
      for (int i = 0; i < count && at + 2 <= n; ++i) {
        const int len = (d[at] << 8) | d[at + 1];
        at += 2;
        if (at + len > n) return {};
        units.emplace_back(d + at, d + at + len);
        at += len;
      }
    }
    return units;
  }
  for (int at = next_start_code(d, n, 0); at < n;) {
    const int start = at + 3, next = next_start_code(d, n, start);
    int end = next;
    if (next < n && end > start && d[end - 1] == 0) --end;  // the zero_byte of a 4-byte start code
    units.emplace_back(d + start, d + end);
    at = next;
  }
  return units;
}

}  // namespace

void MovieWriter::copy_frames(const MovieReader& source, int count) {
  Impl& m = *impl_;
  const std::string& from = source.path();
  if (!m.open) throw Error("movie " + m.path + ": copy after close");
  if (m.frames_in != 0) throw Error("movie " + m.path + ": frames can be copied only into an empty movie");
  if (count < 0 || count > source.frame_count())
    throw Error("movie " + from + " holds " + std::to_string(source.frame_count()) + " frames; " +
                std::to_string(count) + " were to be continued");
  if (count == 0) return;
  const AVCodecParameters* par = m.stream->codecpar;
  const std::vector<std::uint8_t>& header = source.stream_header();
  if (source.coded_width() != m.padded_width || source.coded_height() != m.padded_height ||
      header_units(header.data(), int(header.size())) != header_units(par->extradata, par->extradata_size))
    throw Error("movie " + from + " (" + std::to_string(source.coded_width()) + "x" +
                std::to_string(source.coded_height()) + ") was encoded with another frame size or other video settings "
                "than this run's (" + std::to_string(m.padded_width) + "x" + std::to_string(m.padded_height) +
                "): its frames cannot be continued");
  if (!source.in_decode_order() || !source.is_keyframe(0))
    throw Error("movie " + from + ": frames are not stored in presentation order from a keyframe; cannot continue it");
  const int length_size = header.size() >= 7 && header[0] == 1 ? (header[4] & 3) + 1 : 0;
  // The MP4 muxer converts packets to length-prefixed NAL units itself when the stream header it
  // got is Annex B (libx264's global header); then it must get Annex B packets.
  const bool to_annex_b = length_size && par->extradata_size > 0 && par->extradata[0] != 1;
  std::vector<std::uint8_t> bytes, annex_b;
  for (int f = 0; f < count; ++f) {
    source.read_packet(f, bytes);
    // A damaged picture must not be carried into the continued movie as if it were good.
    if (length_size && verify_packet_checksum(bytes.data(), int(bytes.size()), length_size) == PacketChecksum::bad)
      throw Error("movie " + from + ": frame " + std::to_string(f) + " is damaged (checksum mismatch); cannot continue it");
    // Stored length-prefixed (MP4); handed to the muxer as the encoder's packets are, in Annex B
    // (start codes), which it converts back: the NAL units stay byte for byte.
    annex_b.clear();
    for (std::size_t at = 0; to_annex_b && at + std::size_t(length_size) <= bytes.size();) {
      std::size_t len = 0;
      for (int i = 0; i < length_size; ++i) len = (len << 8) | bytes[at + std::size_t(i)];
      at += std::size_t(length_size);
      if (len > bytes.size() - at) throw Error("movie " + from + ": frame " + std::to_string(f) + " is damaged (bad NAL length)");
      annex_b.insert(annex_b.end(), {0, 0, 0, 1});
      annex_b.insert(annex_b.end(), bytes.begin() + std::ptrdiff_t(at), bytes.begin() + std::ptrdiff_t(at + len));
      at += len;
    }
    const std::vector<std::uint8_t>& data = to_annex_b ? annex_b : bytes;
    if (av_new_packet(m.pkt, int(data.size())) < 0) throw Error("movie " + m.path + ": out of memory");
    std::memcpy(m.pkt->data, data.data(), data.size());
    m.pkt->pts = m.pkt->dts = f;
    m.pkt->duration = 1;
    if (source.is_keyframe(f)) m.pkt->flags |= AV_PKT_FLAG_KEY;
    // Already checksummed (and the first packet already carries the encoder's version SEI).
    av_packet_rescale_ts(m.pkt, m.enc_time_base, m.stream->time_base);
    m.pkt->stream_index = m.stream->index;
    const int ret = av_write_frame(m.fmt, m.pkt);
    av_packet_unref(m.pkt);
    if (ret < 0) m.fail_write("cannot write copied frame " + std::to_string(f), ret);
    m.check_io("cannot write copied frame " + std::to_string(f));
    ++m.packets_out;
    ++m.frames_in;
  }
}

void MovieWriter::flush() {
  Impl& m = *impl_;
  if (!m.open) return;
  if (m.failed) throw FileError(m.path, "an earlier write failed; the movie ends at its last flushed frame");
  // With the settings of H264Encoder x264 returns each packet at once; should a configuration ever
  // hold frames back, drain it (a fresh encoder starts with a keyframe at the next append).
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
