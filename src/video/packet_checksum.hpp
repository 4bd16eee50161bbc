#pragma once
// A CRC-32 of every coded picture, carried inside the picture's own packet as an H.264 SEI message
// (user_data_unregistered, our UUID), so a reader can tell a damaged packet from a good one even when
// the damage decodes "validly": zeroed or flipped CABAC data often decodes without any error the
// decoder could report, as skipped macroblocks (a copy of the previous frame) or as garbage.
// Decoders and other players ignore the message. Movies without it are simply not checked.
#include <cstdint>

extern "C" {
#include <libavcodec/packet.h>
}

namespace panoptes::video {

/// Appends the checksum SEI to an Annex B H.264 packet (as libx264 produces them). Returns false and
/// leaves the packet unchanged if it is not Annex B or memory runs out.
bool append_packet_checksum(AVPacket* pkt);

/// Result of verify_packet_checksum.
enum class PacketChecksum { absent, good, bad };

/// Checks a length-prefixed (MP4 "avcC") H.264 packet whose NAL length fields have `length_size`
/// bytes: `bad` if its NAL structure is broken or the CRC of its other NAL units differs from the
/// recorded one, else `absent` if it carries no checksum SEI (a reader that saw checksums in a movie's
/// first packet treats `absent` in a later one as damage too).
PacketChecksum verify_packet_checksum(const std::uint8_t* data, int size, int length_size);

}  // namespace panoptes::video
