#include "video/packet_checksum.hpp"

#include <array>
#include <cstring>
#include <vector>

extern "C" {
#include <libavutil/crc.h>
#include <libavutil/mem.h>
}

#include "video/annex_b.hpp"

namespace panoptes::video {

namespace {

// "panoptes-crc32-1" as the SEI's UUID.
constexpr std::array<std::uint8_t, 16> kUuid = {'p', 'a', 'n', 'o', 'p', 't', 'e', 's',
                                                '-', 'c', 'r', 'c', '3', '2', '-', '1'};
constexpr int kPayloadSize = 16 + 4;

std::uint32_t crc_update(std::uint32_t crc, const std::uint8_t* p, std::size_t n) {
  return av_crc(av_crc_get_table(AV_CRC_32_IEEE_LE), crc, p, n);
}

// NAL payload without its trailing zero bytes (the MP4 muxer drops them when it converts Annex B).
std::size_t trimmed(const std::uint8_t* p, std::size_t n) {
  while (n > 0 && p[n - 1] == 0) --n;
  return n;
}

// True if the NAL unit (header byte first, escaped) is our checksum SEI; then *crc is its value.
bool is_checksum_sei(const std::uint8_t* nal, std::size_t n, std::uint32_t* crc) {
  if (n < 3 || (nal[0] & 0x1f) != 6 || nal[1] != 5 || nal[2] != kPayloadSize) return false;
  // Unescape (remove emulation-prevention 0x03 after 00 00) the payload.
  std::uint8_t payload[kPayloadSize];
  int got = 0, zeros = 0;
  for (std::size_t i = 3; i < n && got < kPayloadSize; ++i) {
    if (zeros >= 2 && nal[i] == 3) {
      zeros = 0;
      continue;
    }
    zeros = nal[i] == 0 ? zeros + 1 : 0;
    payload[got++] = nal[i];
  }
  if (got != kPayloadSize || std::memcmp(payload, kUuid.data(), kUuid.size()) != 0) return false;
  *crc = std::uint32_t(payload[16]) << 24 | std::uint32_t(payload[17]) << 16 | std::uint32_t(payload[18]) << 8 |
         payload[19];
  return true;
}

}  // namespace

bool append_packet_checksum(AVPacket* pkt) {
  const std::uint8_t* d = pkt->data;
  const int n = pkt->size;
  auto start_code = [&](int from) { return next_start_code(d, n, from); };
  int sc = start_code(0);
  if (n < 4 || !is_annex_b(d, sc)) return false;
  std::uint32_t crc = 0;
  int first_vcl = -1;  // where the SEI goes: SEI must precede the first slice of an access unit
  while (sc < n) {
    const int next = start_code(sc + 3);
    const std::uint8_t* nal = d + sc + 3;
    const int type = sc + 3 < n ? (nal[0] & 0x1f) : 0;
    if (first_vcl < 0 && type >= 1 && type <= 5) first_vcl = sc > 0 && d[sc - 1] == 0 ? sc - 1 : sc;
    crc = crc_update(crc, nal, trimmed(nal, std::size_t(next - sc - 3)));
    sc = next;
  }
  if (first_vcl < 0) first_vcl = n;
  std::vector<std::uint8_t> sei = {0, 0, 0, 1, 0x06, 0x05, kPayloadSize};
  std::uint8_t payload[kPayloadSize];
  std::memcpy(payload, kUuid.data(), kUuid.size());
  for (int i = 0; i < 4; ++i) payload[16 + i] = std::uint8_t(crc >> (24 - 8 * i));
  int zeros = 0;
  for (std::uint8_t b : payload) {
    if (zeros >= 2 && b <= 3) {  // emulation prevention
      sei.push_back(3);
      zeros = 0;
    }
    sei.push_back(b);
    zeros = b == 0 ? zeros + 1 : 0;
  }
  sei.push_back(0x80);  // rbsp trailing bits
  if (av_grow_packet(pkt, int(sei.size())) < 0) return false;
  std::memmove(pkt->data + first_vcl + sei.size(), pkt->data + first_vcl, std::size_t(n - first_vcl));
  std::memcpy(pkt->data + first_vcl, sei.data(), sei.size());
  return true;
}

PacketChecksum verify_packet_checksum(const std::uint8_t* data, int size, int length_size) {
  if (length_size < 1 || length_size > 4) return PacketChecksum::absent;
  std::uint32_t crc = 0, recorded = 0;
  bool found = false;
  for (int pos = 0; pos < size;) {
    if (size - pos < length_size) return PacketChecksum::bad;
    std::uint32_t len = 0;
    for (int i = 0; i < length_size; ++i) len = len << 8 | data[pos + i];
    pos += length_size;
    if (len > std::uint32_t(size - pos)) return PacketChecksum::bad;
    const std::uint8_t* nal = data + pos;
    std::uint32_t value = 0;
    if (is_checksum_sei(nal, len, &value)) {
      recorded = value;
      found = true;
    } else {
      crc = crc_update(crc, nal, trimmed(nal, len));
    }
    pos += int(len);
  }
  if (!found) return PacketChecksum::absent;
  return crc == recorded ? PacketChecksum::good : PacketChecksum::bad;
}

}  // namespace panoptes::video
