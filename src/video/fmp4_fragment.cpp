#include "video/fmp4_fragment.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

#include <cstring>
#include <string>

#include "core/error.hpp"
#include "video/ffmpeg_util.hpp"
#include "video/video_settings.hpp"

namespace panoptes::video {

namespace {

void put32(std::vector<std::uint8_t>& o, std::uint32_t v) {
  o.push_back(std::uint8_t(v >> 24));
  o.push_back(std::uint8_t(v >> 16));
  o.push_back(std::uint8_t(v >> 8));
  o.push_back(std::uint8_t(v));
}
void put64(std::vector<std::uint8_t>& o, std::uint64_t v) {
  put32(o, std::uint32_t(v >> 32));
  put32(o, std::uint32_t(v));
}
void box(std::vector<std::uint8_t>& o, std::uint32_t size, const char* type) {
  put32(o, size);
  o.insert(o.end(), type, type + 4);
}

// Sample flags of ISO/IEC 14496-12 8.8.3.1 as FFmpeg's mov muxer writes them: a sync sample depends on
// no other; any other sample depends on others and is not a sync sample.
constexpr std::uint32_t kSyncSample = 0x02000000;
constexpr std::uint32_t kNonSyncSample = 0x01010000;

constexpr std::size_t kMoofFixed = 8 + 16 + 8 + 16 + 20 + 20;  // moof, mfhd, traf, tfhd, tfdt(v1), trun
constexpr std::size_t kPerSample = 12;                         // trun: duration, size, flags

}  // namespace

std::size_t fragment_overhead(std::size_t samples) { return kMoofFixed + kPerSample * samples + 8; }

std::vector<std::uint8_t> make_init_segment(const std::vector<std::uint8_t>& header, int width, int height,
                                            const VideoSettings& settings, std::uint32_t* timescale,
                                            std::uint32_t* frame_ticks) {
  quiet_ffmpeg_logs();
  AVFormatContext* fmt = nullptr;
  int ret = avformat_alloc_output_context2(&fmt, nullptr, "mp4", nullptr);
  if (ret < 0 || !fmt) throw Error("init segment: cannot allocate the MP4 muxer: " + av_error_string(ret));
  struct Guard {
    AVFormatContext* f;
    ~Guard() {
      if (f->pb) {
        std::uint8_t* b = nullptr;
        avio_close_dyn_buf(f->pb, &b);
        av_free(b);
        f->pb = nullptr;
      }
      avformat_free_context(f);
    }
  } guard{fmt};
  AVStream* st = avformat_new_stream(fmt, nullptr);
  if (!st) throw Error("init segment: out of memory");
  const AVRational rate = av_d2q(settings.fps, 1 << 20);
  st->time_base = av_inv_q(rate);
  st->avg_frame_rate = rate;
  AVCodecParameters* par = st->codecpar;
  par->codec_type = AVMEDIA_TYPE_VIDEO;
  par->codec_id = AV_CODEC_ID_H264;
  par->width = width;
  par->height = height;
  par->format = AV_PIX_FMT_YUV420P;
  // As H264Encoder tags its stream (BT.601, limited range): the init must say what MovieWriter's says.
  par->color_range = AVCOL_RANGE_MPEG;
  par->color_primaries = AVCOL_PRI_SMPTE170M;
  par->color_trc = AVCOL_TRC_SMPTE170M;
  par->color_space = AVCOL_SPC_SMPTE170M;
  par->extradata = static_cast<std::uint8_t*>(av_mallocz(header.size() + AV_INPUT_BUFFER_PADDING_SIZE));
  if (!par->extradata) throw Error("init segment: out of memory");
  std::memcpy(par->extradata, header.data(), header.size());
  par->extradata_size = int(header.size());
  if ((ret = avio_open_dyn_buf(&fmt->pb)) < 0) throw Error("init segment: " + av_error_string(ret));
  AVDictionary* opts = nullptr;
  av_dict_set(&opts, "movflags", "frag_keyframe+empty_moov+default_base_moof", 0);
  ret = avformat_write_header(fmt, &opts);
  av_dict_free(&opts);
  if (ret < 0) throw Error("init segment: the MP4 muxer refused the stream header: " + av_error_string(ret));
  avio_flush(fmt->pb);
  std::uint8_t* bytes = nullptr;
  const int n = avio_close_dyn_buf(fmt->pb, &bytes);
  fmt->pb = nullptr;
  std::vector<std::uint8_t> out(bytes, bytes + std::max(n, 0));
  av_free(bytes);
  *timescale = std::uint32_t(st->time_base.den);
  *frame_ticks = std::uint32_t(av_rescale_q(1, av_inv_q(rate), st->time_base));
  if (out.size() < 16 || *timescale == 0 || *frame_ticks == 0 || st->time_base.num != 1)
    throw Error("init segment: the MP4 muxer gave an unexpected header (" + std::to_string(out.size()) + " bytes)");
  // The muxer may free the codec parameters' extradata with the context: nothing of it is kept.
  return out;
}

void append_fragment(std::vector<std::uint8_t>& o, std::uint32_t sequence, std::uint64_t first_decode_time,
                     std::uint32_t frame_ticks, const std::vector<FragmentSample>& samples, const std::uint8_t* data,
                     std::size_t data_size) {
  const std::size_t n = samples.size();
  const std::size_t moof = kMoofFixed + kPerSample * n;
  if (moof > 0xffffffffu || data_size + 8 > 0xffffffffu) throw Error("fragment too large for 32-bit box sizes");
  // No reserve(): callers batch many fragments into one buffer, which must grow geometrically.
  box(o, std::uint32_t(moof), "moof");
  box(o, 16, "mfhd");
  put32(o, 0);  // version, flags
  put32(o, sequence);
  box(o, std::uint32_t(moof - 8 - 16), "traf");
  box(o, 16, "tfhd");
  put32(o, 0x020000);  // default-base-is-moof: data offsets count from this moof
  put32(o, 1);         // track_ID (the init's only track)
  box(o, 20, "tfdt");
  put32(o, 0x01000000);  // version 1: 64-bit decode time
  put64(o, first_decode_time);
  box(o, std::uint32_t(20 + kPerSample * n), "trun");
  put32(o, 0x000701);  // data-offset, sample-duration, sample-size, sample-flags present
  put32(o, std::uint32_t(n));
  put32(o, std::uint32_t(moof + 8));  // first sample: right after the mdat header
  for (const FragmentSample& s : samples) {
    put32(o, frame_ticks);
    put32(o, s.size);
    put32(o, s.key ? kSyncSample : kNonSyncSample);
  }
  box(o, std::uint32_t(8 + data_size), "mdat");
  o.insert(o.end(), data, data + data_size);
}

std::size_t annex_b_to_mp4(const std::uint8_t* d, std::size_t size, std::vector<std::uint8_t>& out) {
  // Start of the start code at or after `from` (00 00 01), moved back over one zero_byte: the same
  // cut as FFmpeg's ff_avc_find_startcode, so units come out byte for byte as the mov muxer's.
  auto find = [&](std::size_t from) {
    std::size_t k = from;
    for (; k + 2 < size; ++k)
      if (d[k] == 0 && d[k + 1] == 0 && d[k + 2] == 1) break;
    if (k + 2 >= size) return size;
    if (k > from && d[k - 1] == 0) --k;
    return k;
  };
  const std::size_t before = out.size();
  std::size_t at = find(0);
  for (;;) {
    while (at < size && d[at++] == 0) {
    }
    if (at >= size) break;
    const std::size_t end = find(at);
    const std::size_t len = end - at;
    out.push_back(std::uint8_t(len >> 24));
    out.push_back(std::uint8_t(len >> 16));
    out.push_back(std::uint8_t(len >> 8));
    out.push_back(std::uint8_t(len));
    out.insert(out.end(), d + at, d + end);
    at = end;
  }
  return out.size() - before;
}

}  // namespace panoptes::video
