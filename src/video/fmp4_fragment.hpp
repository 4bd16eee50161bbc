#pragma once
// The two pieces of a fragmented MP4 that a packed database stores apart: the init segment
// (ftyp + moov, made once by FFmpeg's mov muxer) and media fragments (moof + mdat, written here box by
// box). An init segment followed by a movie's fragments in frame order is a standard fragmented MP4
// (ISO/IEC 14496-12 with movie fragments): ffmpeg, browsers (MSE) and MovieReader play it.
#include <cstdint>
#include <vector>

namespace panoptes::video {

struct VideoSettings;

/// The init segment of an H.264 track of `width` x `height` (coded size) at settings.fps, with the
/// stream header `header` (an Annex B global header, as libx264 gives it, or an avcC record). Made by
/// FFmpeg's mov muxer with the flags MovieWriter uses (empty_moov, default_base_moof), so a file of
/// this init and fragments from append_fragment() is what MovieWriter writes, box for box, except
/// the fragments' own header layout. `timescale` receives the track's time scale (ticks per second)
/// and `frame_ticks` the duration of one frame in it. Throws Error when FFmpeg refuses.
std::vector<std::uint8_t> make_init_segment(const std::vector<std::uint8_t>& header, int width, int height,
                                            const VideoSettings& settings, std::uint32_t* timescale,
                                            std::uint32_t* frame_ticks);

/// One sample of a fragment: an H.264 access unit in MP4 form (4-byte NAL lengths).
struct FragmentSample {
  std::uint32_t size = 0;
  bool key = false;
};

/// Appends one fragment (moof + mdat) of track 1 to `out`: `sequence` (mfhd, > 0, increasing within a
/// movie), the decode time of its first sample in track ticks (tfdt, version 1), every sample lasting
/// `frame_ticks`, sample sizes and sync flags in `samples`, the sample bytes (`data`, the samples
/// back to back) in the mdat. tfhd has default-base-is-moof, so the fragment is position-independent:
/// it plays wherever it is placed after the init segment.
void append_fragment(std::vector<std::uint8_t>& out, std::uint32_t sequence, std::uint64_t first_decode_time,
                     std::uint32_t frame_ticks, const std::vector<FragmentSample>& samples,
                     const std::uint8_t* data, std::size_t data_size);

/// Bytes append_fragment() adds to `data_size` for `samples` samples (the moof and the mdat header).
std::size_t fragment_overhead(std::size_t samples);

/// Converts an Annex B access unit (start codes) to MP4 form (each NAL unit preceded by its 4-byte
/// big-endian length), as FFmpeg's mov muxer does: a 4-byte start code's leading zero is not part of
/// the unit before it. Appends to `out`; returns the bytes appended.
std::size_t annex_b_to_mp4(const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t>& out);

}  // namespace panoptes::video
