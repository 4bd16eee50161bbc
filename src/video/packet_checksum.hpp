#pragma once
// A CRC-32 of every coded picture, carried inside the picture's own packet as an H.264 SEI message
// (user_data_unregistered, our UUID), so a reader can tell a damaged packet from a good one even when
// the damage decodes "validly": zeroed or flipped CABAC data often decodes without any error the
// decoder could report, as skipped macroblocks (a copy of the previous frame) or as garbage.
// Decoders and other players ignore the message. Movies without it are simply not checked.
//
// Version 2 of the message (UUID "panoptes-frame-2") also carries the movie's identity (16 bytes the
// writer's caller chooses: the store puts its database id, camera and task there) and the frame's
// index, so a movie that is not the one a manifest describes (foreign, spliced) and a frame shown at
// another index (a corrupted `tfdt` re-orders fragments) are told from good ones.
#include <array>
#include <cstdint>

extern "C" {
#include <libavcodec/packet.h>
}

namespace panoptes::video {

/// Identity of one movie, carried by every frame's checksum message (version 2).
using MovieIdentity = std::array<std::uint8_t, 16>;

/// What a version-2 checksum message stamps on a packet besides the CRC.
struct FrameStamp {
  MovieIdentity movie{};
  std::uint32_t frame = 0;  ///< index of the frame in its movie
};

/// CRC-32 of the stream's parameter sets (H.264 SPS and PPS NAL units, in order, without their framing)
/// in `header`: an MP4 avcC record or an Annex B global header (the same units give the same value).
/// 0 when the header holds none or is not parseable.
std::uint32_t parameter_sets_crc(const std::uint8_t* header, int size);

/// The identity a version-2 message carries for a movie whose parameter sets are bound to its frames
/// (frame-check scheme 3, issue 44): the caller's identity with the parameter sets' CRC folded into its
/// last four bytes. A flipped bit in the avcC's SPS or PPS (outside every frame's CRC, yet it changes
/// every decoded picture) then shows as a mismatch on every frame.
MovieIdentity bind_parameter_sets(const MovieIdentity& identity, std::uint32_t parameter_sets_crc);

/// Appends the checksum SEI to an Annex B H.264 packet (as libx264 produces them): version 2 with
/// `stamp` when given, else version 1 (CRC only). Returns false and leaves the packet unchanged if it
/// is not Annex B or memory runs out.
bool append_packet_checksum(AVPacket* pkt, const FrameStamp* stamp = nullptr);

/// Result of verify_packet_checksum.
enum class PacketChecksum { absent, good, bad };

/// Everything a packet's checksum message says.
struct PacketCheck {
  PacketChecksum checksum = PacketChecksum::absent;
  bool has_sei = false;   ///< a checksum message was found (even if the CRC then failed)
  bool stamped = false;   ///< it was version 2: `stamp` holds its identity and frame index
  FrameStamp stamp;
};

/// As verify_packet_checksum, with the message's version-2 stamp.
PacketCheck inspect_packet(const std::uint8_t* data, int size, int length_size);

/// Checks a length-prefixed (MP4 "avcC") H.264 packet whose NAL length fields have `length_size`
/// bytes: `bad` if its NAL structure is broken or the CRC of its other NAL units differs from the
/// recorded one, else `absent` if it carries no checksum SEI (a reader that saw checksums in a movie's
/// first packet treats `absent` in a later one as damage too).
PacketChecksum verify_packet_checksum(const std::uint8_t* data, int size, int length_size);

}  // namespace panoptes::video
