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

// "panoptes-crc32-1" as the SEI's UUID: CRC only.
constexpr std::array<std::uint8_t, 16> kUuid = {'p', 'a', 'n', 'o', 'p', 't', 'e', 's',
                                                '-', 'c', 'r', 'c', '3', '2', '-', '1'};
constexpr int kPayloadSize = 16 + 4;
// "panoptes-frame-2": CRC, movie identity, frame index.
constexpr std::array<std::uint8_t, 16> kUuid2 = {'p', 'a', 'n', 'o', 'p', 't', 'e', 's',
                                                 '-', 'f', 'r', 'a', 'm', 'e', '-', '2'};
constexpr int kPayloadSize2 = 16 + 4 + 16 + 4;
constexpr int kMaxPayload = kPayloadSize2;

std::uint32_t be32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}

std::uint32_t crc_update(std::uint32_t crc, const std::uint8_t* p, std::size_t n) {
  return av_crc(av_crc_get_table(AV_CRC_32_IEEE_LE), crc, p, n);
}

// NAL payload without its trailing zero bytes (the MP4 muxer drops them when it converts Annex B).
std::size_t trimmed(const std::uint8_t* p, std::size_t n) {
  while (n > 0 && p[n - 1] == 0) --n;
  return n;
}

// True if the NAL unit (header byte first, escaped) is our checksum SEI (either version); then *crc
// is its value and, for version 2, *stamp its identity and frame (*stamped = true).
bool is_checksum_sei(const std::uint8_t* nal, std::size_t n, std::uint32_t* crc, FrameStamp* stamp, bool* stamped) {
  if (n < 3 || (nal[0] & 0x1f) != 6 || nal[1] != 5 || (nal[2] != kPayloadSize && nal[2] != kPayloadSize2)) return false;
  const int size = nal[2];
  // Unescape (remove emulation-prevention 0x03 after 00 00) the payload.
  std::uint8_t payload[kMaxPayload];
  int got = 0, zeros = 0;
  for (std::size_t i = 3; i < n && got < size; ++i) {
    if (zeros >= 2 && nal[i] == 3) {
      zeros = 0;
      continue;
    }
    zeros = nal[i] == 0 ? zeros + 1 : 0;
    payload[got++] = nal[i];
  }
  if (got != size) return false;
  const auto& uuid = size == kPayloadSize ? kUuid : kUuid2;
  if (std::memcmp(payload, uuid.data(), uuid.size()) != 0) return false;
  *crc = be32(payload + 16);
  *stamped = size == kPayloadSize2;
  if (*stamped) {
    std::memcpy(stamp->movie.data(), payload + 20, 16);
    stamp->frame = be32(payload + 36);
  }
  return true;
}

}  // namespace

std::uint32_t parameter_sets_crc(const std::uint8_t* h, int n) {
  if (!h || n <= 0) return 0;
  std::uint32_t crc = 0;
  bool any = false;
  auto add = [&](const std::uint8_t* nal, std::size_t len) {
    if (len == 0) return;
    const int type = nal[0] & 0x1f;
    if (type != 7 && type != 8) return;
    crc = crc_update(crc, nal, trimmed(nal, len));
    any = true;
  };
  if (h[0] == 1) {  // avcC: version, profile, compat, level, length size, #SPS, (len16, SPS)..., #PPS, (len16, PPS)...
    if (n < 7) return 0;
    int pos = 5;
    for (int list = 0; list < 2; ++list) {
      if (pos >= n) return 0;
      const int count = list == 0 ? (h[pos] & 0x1f) : h[pos];
      ++pos;
      for (int i = 0; i < count; ++i) {
        if (pos + 2 > n) return 0;
        const int len = h[pos] << 8 | h[pos + 1];
        pos += 2;
        if (pos + len > n) return 0;
        add(h + pos, std::size_t(len));
        pos += len;
      }
    }
    return any ? crc : 0;
  }
  int sc = next_start_code(h, n, 0);
  while (sc < n) {
    const int next = next_start_code(h, n, sc + 3);
    if (sc + 3 < n) add(h + sc + 3, std::size_t(next - sc - 3));
    sc = next;
  }
  return any ? crc : 0;
}

MovieIdentity bind_parameter_sets(const MovieIdentity& identity, std::uint32_t crc) {
  MovieIdentity bound = identity;
  for (int i = 0; i < 4; ++i) bound[std::size_t(12 + i)] ^= std::uint8_t(crc >> (24 - 8 * i));
  return bound;
}

bool append_packet_checksum(AVPacket* pkt, const FrameStamp* stamp) {
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
  const int size = stamp ? kPayloadSize2 : kPayloadSize;
  std::vector<std::uint8_t> sei = {0, 0, 0, 1, 0x06, 0x05, std::uint8_t(size)};
  std::uint8_t payload[kMaxPayload];
  std::memcpy(payload, (stamp ? kUuid2 : kUuid).data(), 16);
  for (int i = 0; i < 4; ++i) payload[16 + i] = std::uint8_t(crc >> (24 - 8 * i));
  if (stamp) {
    std::memcpy(payload + 20, stamp->movie.data(), 16);
    for (int i = 0; i < 4; ++i) payload[36 + i] = std::uint8_t(stamp->frame >> (24 - 8 * i));
  }
  int zeros = 0;
  for (int k = 0; k < size; ++k) {
    const std::uint8_t b = payload[k];
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

PacketCheck inspect_packet(const std::uint8_t* data, int size, int length_size) {
  PacketCheck check;
  if (length_size < 1 || length_size > 4) return check;
  std::uint32_t crc = 0, recorded = 0;
  for (int pos = 0; pos < size;) {
    if (size - pos < length_size) {
      check.checksum = PacketChecksum::bad;
      return check;
    }
    std::uint32_t len = 0;
    for (int i = 0; i < length_size; ++i) len = len << 8 | data[pos + i];
    pos += length_size;
    if (len > std::uint32_t(size - pos)) {
      check.checksum = PacketChecksum::bad;
      return check;
    }
    const std::uint8_t* nal = data + pos;
    std::uint32_t value = 0;
    FrameStamp stamp;
    bool stamped = false;
    if (!check.has_sei && is_checksum_sei(nal, len, &value, &stamp, &stamped)) {
      recorded = value;
      check.has_sei = true;
      check.stamped = stamped;
      check.stamp = stamp;
    } else {
      crc = crc_update(crc, nal, trimmed(nal, len));
    }
    pos += int(len);
  }
  if (!check.has_sei) return check;
  check.checksum = crc == recorded ? PacketChecksum::good : PacketChecksum::bad;
  return check;
}

PacketChecksum verify_packet_checksum(const std::uint8_t* data, int size, int length_size) {
  return inspect_packet(data, size, length_size).checksum;
}

}  // namespace panoptes::video
