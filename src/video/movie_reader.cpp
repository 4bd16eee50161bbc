// MovieReader: exact random access into an H.264 fragmented MP4 through a packet index.
// Sections (each marked "// --- name ---" below):
//   limits       packet records; what a movie may make FFmpeg allocate
//   state        MovieReader::Impl: the packet index, the decoder's position, damage since the last seek
//   file access  the readable prefix of the file and FFmpeg's I/O callbacks
//   index        build_index: one demux at open, packets in decode order, frames by pts
//   decoding     packet checks, send, seek, decode one frame, export YUV
//   public API   open, crop, sizes, keyframes, frame checks, raw packets, read
//   rgba         frames as RGBA images
#include "video/movie_reader.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
}

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "video/ffmpeg_util.hpp"
#include "video/mp4_table_check.hpp"
#include "video/packet_checksum.hpp"

namespace panoptes::video {

// --- limits ---
// Named, not anonymous: MovieReader::Impl (declared in the header) holds a vector of them.
namespace movie_reader_detail {
struct PacketInfo {
  std::int64_t pos = 0;  // byte offset of the sample in the file
  int size = 0;
  std::int64_t pts = 0;
  std::int64_t dts = 0;
  bool key = false;
};
}  // namespace movie_reader_detail
using movie_reader_detail::PacketInfo;

namespace {

std::string errno_string(int e) { return std::strerror(e); }

// What a movie may make the decoder allocate: the largest picture a database may hold (the same
// bound as the manifest's image size, store::kMaxImagePixels / kMaxImageSide, 8192x4352 and 16384 a
// side). FFmpeg's own default lets a 2 kB stream ask for INT_MAX-pixel pictures.
constexpr std::int64_t kMaxMoviePixels = std::int64_t(139264) * 256;
constexpr int kMaxMovieSide = 16384;
// Streams the demuxer may create (FFmpeg's default is 1000, each with its own tables); ours have one.
constexpr int kMaxMovieStreams = 16;

}  // namespace

// --- state ---
struct MovieReader::Impl {
  std::string path;
  // The movie's bytes: one whole file, or (a packed database) byte ranges of files read as their
  // concatenation. pieces[i] covers the movie's bytes [start, start + size).
  struct Piece {
    int fd = -1;
    std::int64_t offset = 0, size = 0, start = 0;
  };
  std::vector<Piece> pieces;
  std::vector<int> fds;  // owned, one per distinct file
  std::vector<FilePiece> sources;  // empty: the whole file at `path`
  std::int64_t file_size = 0;

  // The index, built once at open: packets in decode order; frames in presentation (pts) order.
  std::vector<PacketInfo> packets;
  std::vector<std::int64_t> frame_pts;  // sorted
  std::vector<int> frame_packet;        // frame -> its packet
  std::vector<int> frame_start;         // frame -> the keyframe packet decoding must start from
  AVRational time_base{1, 1};
  double fps = 0;
  int coded_width = 0, coded_height = 0;
  int crop_width = 0, crop_height = 0;

  AVCodecContext* dec = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* pkt = nullptr;
  AVBufferRef* storage = nullptr;  // packet bytes, reused while no decoder holds a reference to it
  SwsContext* sws_yuv = nullptr;   // only for decoders that output something other than yuv420p
  YuvFrame scratch;                // read_rgba's frame

  // Decoder position: next packet to send; -1 = decoder not primed (next read seeks).
  int next_packet = -1;
  int current_frame = -1;  // frame held in `frame`, -1 if none
  std::int64_t packets_sent = 0;
  bool draining = false;
  // Set when the decoder reported damage since the last seek (a packet it refused, a frame it had to
  // conceal): every later frame up to the next keyframe may predict from concealed pixels.
  bool tainted = false;
  bool current_damaged = false;  // the frame in `frame` is (or predicts from) concealed data
  bool packet_bad = false;       // the packet just sent failed its checksum or the decoder refused it
  int nal_length_size = 0;       // MP4 (avcC) H.264: bytes of each NAL length field; 0 = not checked
  bool checksummed = false;      // the movie's packets carry checksums (packet_checksum.hpp)
  std::vector<std::uint8_t> header;  // the stream's extradata
  FrameChecks checks;            // what the caller demands of every frame
  MovieIdentity expected_identity{};  // checks.required: what every frame's stamp must say
  std::int64_t pts_step = 0;     // checks.required: the frame duration; frame f must sit at f * pts_step
  std::string bad_reason;        // why the last bad packet was bad, for the damaged frame's message

  ~Impl() {
    avcodec_free_context(&dec);
    av_frame_free(&frame);
    av_packet_free(&pkt);
    av_buffer_unref(&storage);
    sws_freeContext(sws_yuv);
    for (int f : fds) ::close(f);
  }

  // pread over the movie's bytes (the concatenation of the pieces); one call may span pieces.
  ssize_t pread_movie(std::uint8_t* buf, std::size_t n, std::int64_t pos) const {
    std::size_t done = 0;
    while (done < n) {
      const std::int64_t at = pos + std::int64_t(done);
      if (at >= file_size) break;
      auto it = std::upper_bound(pieces.begin(), pieces.end(), at, [](std::int64_t v, const Piece& p) { return v < p.start; });
      const Piece& p = *(it - 1);
      const std::int64_t in = at - p.start;
      const std::size_t want = std::size_t(std::min<std::int64_t>(std::int64_t(n - done), p.size - in));
      const ssize_t got = ::pread(p.fd, buf + done, want, p.offset + in);
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) return done ? ssize_t(done) : -1;
      if (got == 0) break;
      done += std::size_t(got);
    }
    return ssize_t(done);
  }

  int frame_of_pts(std::int64_t pts) const {
    auto it = std::lower_bound(frame_pts.begin(), frame_pts.end(), pts);
    if (it == frame_pts.end() || *it != pts) return -1;
    return int(it - frame_pts.begin());
  }

  // --- file access ---
  // Bytes of the file the demuxer may see. For an MP4 this is the file up to its last complete
  // top-level box, plus a trailing mdat that was cut short (its complete samples are usable); a
  // fragment header (moof) cut short would make FFmpeg refuse the whole file, so it is hidden.
  std::int64_t view_size = 0;
  std::int64_t view_pos = 0;

  std::int64_t readable_prefix() const {
    std::int64_t pos = 0;
    std::uint8_t h[16];
    while (pos < file_size) {
      if (file_size - pos < 8) return pos;
      if (pread_movie(h, 16, pos) < 8) return pos;
      std::uint64_t size = (std::uint64_t(h[0]) << 24) | (std::uint64_t(h[1]) << 16) | (std::uint64_t(h[2]) << 8) | h[3];
      for (int i = 4; i < 8; ++i)
        if (h[i] < 0x20 || h[i] > 0x7e) return pos == 0 ? file_size : pos;  // not an MP4 box: not MP4
      const bool mdat = std::memcmp(h + 4, "mdat", 4) == 0;
      if (size == 1) {
        if (file_size - pos < 16) return pos;
        size = 0;
        for (int i = 8; i < 16; ++i) size = (size << 8) | h[i];
        if (size < 16) return pos == 0 ? file_size : pos;
      } else if (size == 0) {
        return file_size;  // box extends to the end of the file
      } else if (size < 8) {
        return pos == 0 ? file_size : pos;
      }
      if (std::uint64_t(file_size - pos) < size) return mdat ? file_size : pos;
      pos += std::int64_t(size);
    }
    return file_size;
  }

  static int io_read(void* opaque, std::uint8_t* buf, int n) {
    auto* m = static_cast<Impl*>(opaque);
    const std::int64_t left = m->view_size - m->view_pos;
    if (left <= 0) return AVERROR_EOF;
    for (;;) {
      const ssize_t got = m->pread_movie(buf, std::size_t(std::min<std::int64_t>(n, left)), m->view_pos);
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) return AVERROR(errno);
      if (got == 0) return AVERROR_EOF;
      m->view_pos += got;
      return int(got);
    }
  }

  static std::int64_t io_seek(void* opaque, std::int64_t offset, int whence) {
    auto* m = static_cast<Impl*>(opaque);
    switch (whence & ~AVSEEK_FORCE) {
      case AVSEEK_SIZE: return m->view_size;
      case SEEK_SET: m->view_pos = offset; break;
      case SEEK_CUR: m->view_pos += offset; break;
      case SEEK_END: m->view_pos = m->view_size + offset; break;
      default: return AVERROR(EINVAL);
    }
    return m->view_pos;
  }

  // Opens one file of the movie; returns its descriptor and size.
  std::pair<int, std::int64_t> open_file(const std::string& file) {
    // O_NONBLOCK: a FIFO in place of a movie must not block the open (it is refused just below).
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd < 0) throw FileError(file, "cannot open the movie: " + errno_string(errno));
    fds.push_back(fd);
    struct stat sb {};
    if (::fstat(fd, &sb) != 0) throw FileError(file, "cannot open the movie: " + errno_string(errno));
    if (S_ISDIR(sb.st_mode)) throw FileError(file, "is a directory, not a movie");
    if (!S_ISREG(sb.st_mode)) throw FileError(file, "is not a regular file (a FIFO, device or socket); refused");
    return {fd, std::int64_t(sb.st_size)};
  }

  void open_pieces() {
    if (sources.empty()) {
      const auto [fd, size] = open_file(path);
      pieces.push_back({fd, 0, size, 0});
      file_size = size;
      return;
    }
    std::vector<std::pair<std::string, std::pair<int, std::int64_t>>> opened;
    for (const FilePiece& s : sources) {
      auto it = std::find_if(opened.begin(), opened.end(), [&](const auto& o) { return o.first == s.path; });
      if (it == opened.end()) {
        opened.emplace_back(s.path, open_file(s.path));
        it = opened.end() - 1;
      }
      const std::int64_t size = it->second.second;
      if (s.size == 0) continue;
      if (s.offset > std::uint64_t(size) || s.size > std::uint64_t(size) - s.offset)
        throw FileError(s.path, "movie " + path + ": byte range " + std::to_string(s.offset) + "+" +
                                    std::to_string(s.size) + " lies past the end of the file (" + std::to_string(size) +
                                    " bytes)");
      pieces.push_back({it->second.first, std::int64_t(s.offset), std::int64_t(s.size), file_size});
      file_size += std::int64_t(s.size);
    }
  }

  // --- index ---
  void build_index() {
    // O_NONBLOCK: a FIFO in place of a movie must not block the open (it is refused just below).
    open_pieces();
    if (file_size == 0) throw FileError(path, "not a readable movie (the file is empty)");
    view_size = readable_prefix();
    // Before FFmpeg sees the file: its sample tables must fit in it (see mp4_table_check.hpp).
    const ReadAt read = [this](std::uint8_t* buf, std::size_t n, std::int64_t pos) {
      return std::int64_t(pread_movie(buf, n, pos));
    };
    check_mp4_sample_tables(read, view_size, path);

    constexpr int kIoBuffer = 1 << 15;
    auto* io_buf = static_cast<std::uint8_t*>(av_malloc(kIoBuffer));
    AVIOContext* io = io_buf ? avio_alloc_context(io_buf, kIoBuffer, 0, this, &io_read, nullptr, &io_seek) : nullptr;
    AVFormatContext* fmt = io ? avformat_alloc_context() : nullptr;
    if (!fmt) {
      if (io) av_freep(&io->buffer);
      else av_free(io_buf);
      avio_context_free(&io);
      throw Error("out of memory");
    }
    fmt->pb = io;
    fmt->flags |= AVFMT_FLAG_CUSTOM_IO;
    fmt->max_streams = kMaxMovieStreams;
    struct Closer {
      AVFormatContext*& f;
      AVIOContext* io;
      ~Closer() {
        avformat_close_input(&f);  // does not free a custom AVIOContext
        av_freep(&io->buffer);
        avio_context_free(&io);
      }
    } closer{fmt, io};
    int ret = avformat_open_input(&fmt, path.c_str(), nullptr, nullptr);
    if (ret < 0) throw FileError(path, "not a readable movie (" + av_error_string(ret) + ")");

    const int si = av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    if (si < 0) throw FileError(path, "has no video stream");
    AVStream* st = fmt->streams[si];
    for (unsigned i = 0; i < fmt->nb_streams; ++i)
      if (int(i) != si) fmt->streams[i]->discard = AVDISCARD_ALL;
    time_base = st->time_base;
    const AVCodec* codec = avcodec_find_decoder(st->codecpar->codec_id);
    if (!codec)
      throw FileError(path, std::string("has no decoder for its video codec ") +
                                avcodec_get_name(st->codecpar->codec_id));
    coded_width = st->codecpar->width;
    coded_height = st->codecpar->height;
    if (coded_width <= 0 || coded_height <= 0) throw FileError(path, "video stream has no frame size");
    if (coded_width > kMaxMovieSide || coded_height > kMaxMovieSide ||
        std::int64_t(coded_width) * coded_height > kMaxMoviePixels)
      throw FileError(path, "video frame size " + std::to_string(coded_width) + "x" + std::to_string(coded_height) +
                                " is larger than a movie may be (at most " + std::to_string(kMaxMovieSide) +
                                " a side and " + std::to_string(kMaxMoviePixels) + " pixels)");

    // One pass over the packets (no decoding) gives the exact frame count, even for fragmented or
    // truncated files whose header holds no sample table. Samples cut off by truncation are dropped.
    AVPacket* p = av_packet_alloc();
    if (!p) throw Error("out of memory");
    std::vector<std::int64_t> durations;
    for (;;) {
      ret = av_read_frame(fmt, p);
      if (ret < 0) break;  // end of file, or the truncated tail: keep what was complete
      if (p->stream_index == si) {
        const std::int64_t pts = p->pts != AV_NOPTS_VALUE ? p->pts : p->dts;
        const bool complete = p->pos >= 0 && p->pos + p->size <= view_size && p->size > 0 &&
                              !(p->flags & AV_PKT_FLAG_CORRUPT) && pts != AV_NOPTS_VALUE;
        if (complete) {
          packets.push_back({p->pos, p->size, pts, p->dts, (p->flags & AV_PKT_FLAG_KEY) != 0});
          if (p->duration > 0) durations.push_back(p->duration);
        } else if (p->pos < 0) {
          av_packet_free(&p);
          throw FileError(path, "container gives no packet positions (only MP4/MOV-like files are supported)");
        }
      }
      av_packet_unref(p);
    }
    av_packet_free(&p);
    // The declared sample sizes: a sample cut short by truncation reads back shorter than declared.
    {
      const int n = avformat_index_get_entries_count(st);
      for (int i = 0; i < n; ++i) {
        const AVIndexEntry* e = avformat_index_get_entry(st, i);
        if (!e || e->pos + e->size <= view_size) continue;
        packets.erase(std::remove_if(packets.begin(), packets.end(),
                                     [&](const PacketInfo& pi) { return pi.pos == e->pos; }),
                      packets.end());
      }
    }
    // Decoding needs a keyframe first: anything before the first keyframe cannot be shown.
    const auto first_key = std::find_if(packets.begin(), packets.end(), [](const PacketInfo& pi) { return pi.key; });
    packets.erase(packets.begin(), first_key);

    std::vector<int> order(packets.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = int(i);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return packets[a].pts < packets[b].pts; });
    for (int k : order) {
      if (!frame_pts.empty() && frame_pts.back() == packets[k].pts) continue;  // duplicate pts: unaddressable
      frame_pts.push_back(packets[k].pts);
      frame_packet.push_back(k);
    }
    // Start packet of each frame: the last keyframe at or before its packet in decode order whose pts
    // is not after the frame's (for streams without B-frames, simply the keyframe at or before it).
    std::vector<int> last_key(packets.size(), 0);
    for (std::size_t k = 0, lk = 0; k < packets.size(); ++k) {
      if (packets[k].key) lk = k;
      last_key[k] = int(lk);
    }
    frame_start.resize(frame_pts.size());
    for (std::size_t f = 0; f < frame_pts.size(); ++f) {
      int k = last_key[frame_packet[f]];
      while (k > 0 && packets[k].pts > frame_pts[f]) k = last_key[k - 1];
      frame_start[f] = k;
    }

    // Frame rate: the median packet duration, else the median pts step, else the container's guess.
    if (durations.empty())
      for (std::size_t f = 1; f < frame_pts.size(); ++f) durations.push_back(frame_pts[f] - frame_pts[f - 1]);
    if (!durations.empty()) {
      std::nth_element(durations.begin(), durations.begin() + durations.size() / 2, durations.end());
      fps = 1.0 / (double(durations[durations.size() / 2]) * av_q2d(time_base));
    } else if (st->avg_frame_rate.num > 0 && st->avg_frame_rate.den > 0) {
      fps = av_q2d(st->avg_frame_rate);
    } else {
      fps = 30;
    }

    dec = avcodec_alloc_context3(codec);
    if (!dec) throw Error("out of memory");
    ret = avcodec_parameters_to_context(dec, st->codecpar);
    if (ret < 0) throw FileError(path, "bad codec parameters: " + av_error_string(ret));
    dec->pkt_timebase = time_base;
    // One thread: no frame delay, so a frame comes out as soon as its packet goes in. The player runs
    // many readers in parallel instead.
    dec->thread_count = 1;
    // The container's size is checked above; the stream's own (SPS) may claim another, and a 2 kB
    // stream of skipped macroblocks claiming 35 Mpixel pictures costs seconds per packet to decode. A
    // picture may be no larger than about what the container says: FFmpeg checks its buffers' size
    // (width aligned to the SIMD stride, up to 64), so allow twice that, within kMaxMoviePixels.
    dec->max_pixels = std::min(kMaxMoviePixels,
                               2 * std::int64_t((coded_width + 63) / 64 * 64) * ((coded_height + 15) / 16 * 16));
    ret = avcodec_open2(dec, codec, nullptr);
    if (ret < 0) throw FileError(path, "cannot open the video decoder: " + av_error_string(ret));

    std::size_t max_size = 0;
    for (const auto& pi : packets) max_size = std::max(max_size, std::size_t(pi.size));
    storage = av_buffer_allocz(int(max_size + AV_INPUT_BUFFER_PADDING_SIZE));
    frame = av_frame_alloc();
    pkt = av_packet_alloc();
    if (!storage || !frame || !pkt) throw Error("out of memory");

    crop_width = coded_width;
    crop_height = coded_height;

    // Packets written by MovieWriter carry a checksum. A database that records its frame checks says
    // so (checks.required); otherwise one of the first packets carrying a checksum message (good or
    // damaged: a damaged first packet must not switch the checks off) means every packet must.
    const AVCodecParameters* par = st->codecpar;
    if (par->extradata_size > 0) header.assign(par->extradata, par->extradata + par->extradata_size);
    if (par->codec_id == AV_CODEC_ID_H264 && par->extradata_size >= 7 && par->extradata[0] == 1)
      nal_length_size = (par->extradata[4] & 3) + 1;
    if (checks.required) {
      checksummed = true;
      expected_identity = checks.parameter_sets
                              ? bind_parameter_sets(checks.identity, parameter_sets_crc(header.data(), int(header.size())))
                              : checks.identity;
      // Every frame lasts one frame duration (MovieWriter writes constant frame rate from 0).
      pts_step = durations.empty() ? 0 : durations[durations.size() / 2];
    } else if (nal_length_size > 0) {
      std::vector<std::uint8_t> bytes;
      for (std::size_t k = 0; k < packets.size() && k < 3 && !checksummed; ++k) {
        bytes.resize(std::size_t(packets[k].size));
        if (pread_movie(bytes.data(), bytes.size(), packets[k].pos) == ssize_t(bytes.size()))
          checksummed = inspect_packet(bytes.data(), packets[k].size, nal_length_size).has_sei;
      }
    }
  }

  // --- decoding ---
  // True if packet k's bytes pass the checks; else sets bad_reason.
  bool packet_ok(int k, const std::uint8_t* data) {
    const PacketInfo& pi = packets[std::size_t(k)];
    if (!checks.required) {
      if (nal_length_size > 0 && verify_packet_checksum(data, pi.size, nal_length_size) == PacketChecksum::good) return true;
      bad_reason = "its checksum does not match";
      return false;
    }
    const PacketCheck c = nal_length_size > 0 ? inspect_packet(data, pi.size, nal_length_size) : PacketCheck{};
    const int f = frame_of_pts(pi.pts);
    if (!c.has_sei || !c.stamped) {
      bad_reason = "it carries no frame checksum although its database records that every frame has one";
    } else if (c.checksum != PacketChecksum::good) {
      bad_reason = "its checksum does not match";
    } else if (c.stamp.movie != expected_identity) {
      // Scheme 3 binds the parameter sets into the identity's last 4 bytes: the rest still matching
      // means the frame is this movie's and the movie's SPS/PPS are not the ones it was encoded with.
      const bool same_movie = checks.parameter_sets &&
                              std::equal(c.stamp.movie.begin(), c.stamp.movie.begin() + 12, checks.identity.begin());
      bad_reason = same_movie ? "the movie's parameter sets (SPS/PPS in its avcC box) are not the ones its frames were "
                                "encoded with (a damaged stream header changes every picture)"
                              : "it belongs to another movie (foreign or spliced)";
    } else if (f < 0 || c.stamp.frame != std::uint32_t(f)) {
      bad_reason = "it is frame " + std::to_string(c.stamp.frame) + " of its movie, shown at index " + std::to_string(f) +
                   " (re-ordered or spliced timestamps)";
    } else if (pts_step <= 0 || pi.pts != std::int64_t(f) * pts_step) {
      bad_reason = "its timestamp " + std::to_string(pi.pts) + " does not match its index " + std::to_string(f) +
                   " (expected " + std::to_string(std::int64_t(f) * pts_step) + ")";
    } else {
      return true;
    }
    return false;
  }

  void send_packet(int k) {
    const PacketInfo& pi = packets[k];
    if (!av_buffer_is_writable(storage)) {  // the decoder still holds the previous packet's bytes
      AVBufferRef* fresh = av_buffer_allocz(storage->size);
      if (!fresh) throw Error("out of memory");
      av_buffer_unref(&storage);
      storage = fresh;
    }
    std::int64_t done = 0;
    while (done < pi.size) {
      const ssize_t n = pread_movie(storage->data + done, std::size_t(pi.size - done), pi.pos + done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw FileError(path, "cannot read frame data at byte " + std::to_string(pi.pos + done) + ": " +
                                            (n < 0 ? errno_string(errno) : "file shrank"));
      done += n;
    }
    std::memset(storage->data + pi.size, 0, AV_INPUT_BUFFER_PADDING_SIZE);
    // Accumulates until a frame comes out: a bad packet whose picture never appears still taints
    // the next picture (it may predict from the lost one).
    if (checksummed && !packet_ok(k, storage->data)) packet_bad = true;
    pkt->buf = av_buffer_ref(storage);
    if (!pkt->buf) throw Error("out of memory");
    pkt->data = storage->data;
    pkt->size = pi.size;
    pkt->pts = pi.pts;
    pkt->dts = pi.dts;
    pkt->flags = pi.key ? AV_PKT_FLAG_KEY : 0;
    const int ret = avcodec_send_packet(dec, pkt);
    av_packet_unref(pkt);
    ++packets_sent;
    // A damaged packet is not fatal by itself: the frame it carried never comes out (or comes out
    // concealed), and the frames predicted from it are flagged (see `tainted`).
    if (ret == AVERROR_INVALIDDATA) {
      packet_bad = true;
      bad_reason = "the decoder refused its data";
    }
    if (ret < 0 && ret != AVERROR_INVALIDDATA)
      throw Error("movie " + path + ": decoder refused packet " + std::to_string(k) + ": " + av_error_string(ret));
  }

  void seek_to(int start_packet) {
    avcodec_flush_buffers(dec);
    packet_bad = false;
    bad_reason.clear();
    next_packet = start_packet;
    current_frame = -1;
    draining = false;
    tainted = false;
  }

  // Leaves frame `index` in `frame`.
  void decode(int index) {
    if (index < 0 || index >= int(frame_pts.size()))
      throw Error("movie " + path + ": frame " + std::to_string(index) + " is out of range (the movie has " +
                  std::to_string(frame_pts.size()) + " frames)");
    if (index == current_frame && next_packet >= 0) return;
    // Decoding on from where we are is never slower than seeking when the frame's keyframe has
    // already been sent; otherwise jump to that keyframe.
    if (!(next_packet >= 0 && current_frame < index && frame_start[index] <= next_packet))
      seek_to(frame_start[index]);
    try {
      for (;;) {
        int ret = avcodec_receive_frame(dec, frame);
        if (ret == 0) {
          const std::int64_t pts = frame->pts != AV_NOPTS_VALUE ? frame->pts : frame->best_effort_timestamp;
          const int f = frame_of_pts(pts);
          // A clean keyframe ends the damage; a bad packet, concealment or a corrupt flag starts it
          // (no decoder delay: the frame out is the packet just sent).
          const bool bad = packet_bad || frame->decode_error_flags != 0 || (frame->flags & AV_FRAME_FLAG_CORRUPT);
          packet_bad = false;
          tainted = frame->key_frame ? bad : (tainted || bad);
          current_damaged = tainted;
          if (f < 0) {  // not a frame of the index (e.g. from a dropped, truncated packet)
            current_frame = -1;
            continue;
          }
          current_frame = f;
          if (f == index) return;
          if (f > index) break;  // frame `index` was skipped by the decoder: damaged
          continue;
        }
        if (ret == AVERROR(EAGAIN)) {
          if (next_packet < int(packets.size())) {
            send_packet(next_packet++);
          } else if (!draining) {
            draining = true;
            ret = avcodec_send_packet(dec, nullptr);
            if (ret < 0 && ret != AVERROR_EOF) break;
          } else {
            break;
          }
          continue;
        }
        if (ret == AVERROR_EOF) break;
        if (ret == AVERROR_INVALIDDATA) {
          tainted = true;  // a picture the decoder gave up on: later ones may predict from it
          continue;
        }
        throw Error("movie " + path + ": decoding failed: " + av_error_string(ret));
      }
    } catch (...) {
      next_packet = -1;
      current_frame = -1;
      throw;
    }
    next_packet = -1;
    current_frame = -1;
    throw DamagedFrameError("movie " + path + ": frame " + std::to_string(index) + " cannot be decoded (damaged data)");
  }

  void export_yuv(YuvFrame& out) {
    const int w = crop_width, h = crop_height;
    const int cw = (w + 1) / 2, ch = (h + 1) / 2;
    out.width = w;
    out.height = h;
    out.index = current_frame;
    out.y.resize(std::size_t(w) * h);
    out.u.resize(std::size_t(cw) * ch);
    out.v.resize(std::size_t(cw) * ch);
    if (frame->format == AV_PIX_FMT_YUV420P && frame->width >= w && frame->height >= h) {
      for (int y = 0; y < h; ++y) std::memcpy(out.y.data() + std::size_t(y) * w, frame->data[0] + y * frame->linesize[0], w);
      for (int y = 0; y < ch; ++y) {
        std::memcpy(out.u.data() + std::size_t(y) * cw, frame->data[1] + y * frame->linesize[1], cw);
        std::memcpy(out.v.data() + std::size_t(y) * cw, frame->data[2] + y * frame->linesize[2], cw);
      }
      return;
    }
    // Other decoder outputs (full-range, 4:2:2, 10-bit, ...) are converted to what YuvFrame promises.
    if (frame->width < w || frame->height < h)
      throw Error("movie " + path + ": decoded frame is smaller than the crop");
    sws_yuv = sws_getCachedContext(sws_yuv, w, h, AVPixelFormat(frame->format), w, h, AV_PIX_FMT_YUV420P,
                                   SWS_BILINEAR | SWS_ACCURATE_RND, nullptr, nullptr, nullptr);
    if (!sws_yuv) throw Error("movie " + path + ": cannot convert its pixel format to yuv420p");
    std::uint8_t* dst[3] = {out.y.data(), out.u.data(), out.v.data()};
    int dst_stride[3] = {w, cw, cw};
    sws_scale(sws_yuv, frame->data, frame->linesize, 0, h, dst, dst_stride);
  }
};

// --- public API ---
MovieReader::MovieReader(const std::string& path, const FrameChecks& checks) : impl_(std::make_unique<Impl>()) {
  quiet_ffmpeg_logs();
  impl_->path = path;
  impl_->checks = checks;
  impl_->build_index();
}

MovieReader::MovieReader(const std::vector<FilePiece>& pieces, const std::string& name, const FrameChecks& checks)
    : impl_(std::make_unique<Impl>()) {
  quiet_ffmpeg_logs();
  if (pieces.empty()) throw FileError(name, "not a readable movie (no byte ranges)");
  impl_->path = name;
  impl_->sources = pieces;
  impl_->checks = checks;
  impl_->build_index();
}

MovieReader::~MovieReader() = default;

void MovieReader::set_crop(int width, int height) {
  Impl& m = *impl_;
  if (width < 1 || height < 1 || width > m.coded_width || height > m.coded_height)
    throw Error("movie " + m.path + ": crop " + std::to_string(width) + "x" + std::to_string(height) +
                " does not fit the coded size " + std::to_string(m.coded_width) + "x" +
                std::to_string(m.coded_height));
  m.crop_width = width;
  m.crop_height = height;
}

int MovieReader::frame_count() const { return int(impl_->frame_pts.size()); }
double MovieReader::fps() const { return impl_->fps; }
double MovieReader::duration() const { return impl_->fps > 0 ? frame_count() / impl_->fps : 0; }
int MovieReader::width() const { return impl_->crop_width; }
int MovieReader::height() const { return impl_->crop_height; }
int MovieReader::coded_width() const { return impl_->coded_width; }
int MovieReader::coded_height() const { return impl_->coded_height; }
const std::string& MovieReader::path() const { return impl_->path; }

bool MovieReader::is_keyframe(int index) const {
  const Impl& m = *impl_;
  if (index < 0 || index >= frame_count()) return false;
  return m.packets[m.frame_packet[index]].key;
}

std::vector<int> MovieReader::check_frames() {
  Impl& m = *impl_;
  std::vector<int> bad;
  if (!m.checksummed) return bad;
  std::vector<std::uint8_t> bytes;
  for (std::size_t k = 0; k < m.packets.size(); ++k) {
    const PacketInfo& pi = m.packets[k];
    bytes.resize(std::size_t(pi.size));
    std::int64_t done = 0;
    while (done < pi.size) {
      const ssize_t n = m.pread_movie(bytes.data() + done, std::size_t(pi.size - done), pi.pos + done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw FileError(m.path, "cannot read frame data at byte " + std::to_string(pi.pos + done));
      done += n;
    }
    const int f = m.frame_of_pts(pi.pts);
    if (f >= 0 && !m.packet_ok(int(k), bytes.data())) bad.push_back(f);
  }
  m.bad_reason.clear();
  std::sort(bad.begin(), bad.end());
  // Frames predicted from a bad one are damaged too, up to the next keyframe.
  std::vector<int> out;
  for (std::size_t i = 0, f = 0; f < m.frame_pts.size(); ++f) {
    while (i < bad.size() && bad[i] < int(f)) ++i;
    const bool own = i < bad.size() && bad[i] == int(f);
    if (own || (!out.empty() && out.back() == int(f) - 1 && !m.packets[std::size_t(m.frame_packet[f])].key))
      out.push_back(int(f));
  }
  return out;
}

std::int64_t MovieReader::packets_decoded() const { return impl_->packets_sent; }

void MovieReader::read_packet(int index, std::vector<std::uint8_t>& out) const {
  const Impl& m = *impl_;
  if (index < 0 || index >= frame_count())
    throw Error("movie " + m.path + ": frame " + std::to_string(index) + " out of range (" +
                std::to_string(frame_count()) + " frames)");
  const PacketInfo& pi = m.packets[std::size_t(m.frame_packet[std::size_t(index)])];
  out.resize(std::size_t(pi.size));
  std::int64_t done = 0;
  while (done < pi.size) {
    const ssize_t n = m.pread_movie(out.data() + done, std::size_t(pi.size - done), pi.pos + done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw FileError(m.path, "cannot read frame data at byte " + std::to_string(pi.pos + done) + ": " +
                                            (n < 0 ? errno_string(errno) : "file shrank"));
    done += n;
  }
}

const std::vector<std::uint8_t>& MovieReader::stream_header() const { return impl_->header; }

bool MovieReader::in_decode_order() const {
  const Impl& m = *impl_;
  if (m.frame_packet.size() != m.packets.size()) return false;
  for (std::size_t f = 0; f < m.frame_packet.size(); ++f)
    if (m.frame_packet[f] != int(f)) return false;
  return true;
}

void MovieReader::read(int index, YuvFrame& out) {
  impl_->decode(index);
  if (impl_->current_damaged)
    throw DamagedFrameError("movie " + impl_->path + ": frame " + std::to_string(index) +
                            " is damaged (" +
                            (impl_->bad_reason.empty()
                                 ? std::string("the decoder had to conceal missing or corrupt data in it or in a frame "
                                               "it predicts from")
                                 : impl_->bad_reason + ", in it or in a frame it predicts from") +
                            ")");
  impl_->export_yuv(out);
}

// --- rgba ---
Image MovieReader::read_rgba(int index) {
  read(index, impl_->scratch);
  return to_rgba(impl_->scratch);
}

Image MovieReader::to_rgba(const YuvFrame& f) {
  const int cw = (f.width + 1) / 2, ch = (f.height + 1) / 2;
  if (f.width < 1 || f.height < 1 || f.y.size() < std::size_t(f.width) * f.height ||
      f.u.size() < std::size_t(cw) * ch || f.v.size() < std::size_t(cw) * ch)
    throw Error("to_rgba: YUV frame planes do not match its size " + std::to_string(f.width) + "x" +
                std::to_string(f.height));
  // The converter works on the even (coded) size: for odd sizes sws would otherwise stretch the
  // ceil(w/2) chroma samples over w pixels and shift colours by up to half a pixel. Odd frames are
  // padded by repeating the last luma column/row (chroma already covers the padded size).
  const int ew = f.width + (f.width & 1), eh = f.height + (f.height & 1);
  struct Cache {
    SwsContext* ctx = nullptr;
    std::vector<std::uint8_t> y, rgba;
    ~Cache() { sws_freeContext(ctx); }
  };
  thread_local Cache cache;
  SwsContext* ctx = sws_getCachedContext(cache.ctx, ew, eh, AV_PIX_FMT_YUV420P, ew, eh, AV_PIX_FMT_RGBA,
                                         SWS_LANCZOS | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr,
                                         nullptr);
  if (!ctx) throw Error("to_rgba: cannot create the YUV to RGB converter");
  if (ctx != cache.ctx) {
    cache.ctx = ctx;
    const int* coeffs = sws_getCoefficients(SWS_CS_ITU601);
    sws_setColorspaceDetails(ctx, coeffs, 0, coeffs, 1, 0, 1 << 16, 1 << 16);
  }
  Image img(f.width, f.height, 4);
  const std::uint8_t* luma = f.y.data();
  if (ew != f.width || eh != f.height) {
    cache.y.resize(std::size_t(ew) * eh);
    for (int y = 0; y < eh; ++y) {
      const std::uint8_t* in = f.y.data() + std::size_t(std::min(y, f.height - 1)) * f.width;
      std::uint8_t* out = cache.y.data() + std::size_t(y) * ew;
      std::memcpy(out, in, f.width);
      if (ew != f.width) out[f.width] = in[f.width - 1];
    }
    luma = cache.y.data();
    cache.rgba.resize(std::size_t(ew) * eh * 4);
  }
  const std::uint8_t* src[3] = {luma, f.u.data(), f.v.data()};
  const int src_stride[3] = {ew, cw, cw};
  const bool padded = ew != f.width || eh != f.height;
  std::uint8_t* dst[1] = {padded ? cache.rgba.data() : img.pixels.data()};
  const int dst_stride[1] = {ew * 4};
  sws_scale(ctx, src, src_stride, 0, eh, dst, dst_stride);
  if (padded)
    for (int y = 0; y < f.height; ++y)
      std::memcpy(img.row(y), cache.rgba.data() + std::size_t(y) * ew * 4, img.stride());
  return img;
}

}  // namespace panoptes::video
