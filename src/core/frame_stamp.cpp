#include "core/frame_stamp.hpp"

#include <algorithm>
#include <string>

#include "core/error.hpp"

namespace panoptes {
namespace {

constexpr std::uint64_t kSync = 0xA;  // 4-bit pattern 1010 in the top bits of the payload
constexpr int kBits = kStampColumns * kStampRows;  // 80 = 64 payload + 16 CRC
static_assert(kBits == 80);

// CRC-16/CCITT-FALSE over the 8 payload bytes (big-endian): detects every error of up to 3 bits and
// all bursts up to 16, so a misread block never yields a wrong stamp silently.
std::uint16_t crc16(std::uint64_t payload) {
  std::uint16_t crc = 0xFFFF;
  for (int byte = 7; byte >= 0; --byte) {
    crc ^= std::uint16_t(((payload >> (8 * byte)) & 0xFF) << 8);
    for (int b = 0; b < 8; ++b) crc = (crc & 0x8000) ? std::uint16_t((crc << 1) ^ 0x1021) : std::uint16_t(crc << 1);
  }
  return crc;
}

std::uint64_t pack(const FrameStamp& s) {
  return (kSync << 60) | (std::uint64_t(s.camera) << 36) | (std::uint64_t(s.task) << 20) | std::uint64_t(s.frame);
}

// Bit i of the 80-bit code: 0..63 are the payload from its most significant bit, 64..79 the CRC.
bool code_bit(std::uint64_t payload, std::uint16_t crc, int i) {
  return i < 64 ? ((payload >> (63 - i)) & 1) : ((crc >> (79 - i)) & 1);
}

}  // namespace

int StampGeometry::width() const { return kStampColumns * block; }
int StampGeometry::height() const { return kStampRows * block; }

StampGeometry stamp_geometry(int width, int height) {
  StampGeometry g;
  g.block = std::max(4, std::min(width, height) / 64);
  if (width < g.width() || height < g.height())
    throw Error("frame stamp: image " + std::to_string(width) + "x" + std::to_string(height) +
                " is too small (the stamp needs at least " + std::to_string(g.width()) + "x" +
                std::to_string(g.height()) + " pixels)");
  return g;
}

void draw_frame_stamp(Image& image, const FrameStamp& stamp) {
  if (stamp.camera > kStampMaxCamera || stamp.task > kStampMaxTask || stamp.frame > kStampMaxFrame)
    throw Error("frame stamp: (camera " + std::to_string(stamp.camera) + ", task " + std::to_string(stamp.task) +
                ", frame " + std::to_string(stamp.frame) + ") out of range (camera < 2^24, task < 2^16, frame < 2^20)");
  if (image.channels != 3 && image.channels != 4)
    throw Error("frame stamp: image has " + std::to_string(image.channels) + " channels, expected 3 or 4");
  const StampGeometry g = stamp_geometry(image.width, image.height);
  const std::uint64_t payload = pack(stamp);
  const std::uint16_t crc = crc16(payload);
  for (int i = 0; i < kBits; ++i) {
    const std::uint8_t v = code_bit(payload, crc, i) ? 255 : 0;
    const int bx = (i % kStampColumns) * g.block, by = (i / kStampColumns) * g.block;
    for (int y = by; y < by + g.block; ++y) {
      std::uint8_t* p = image.at(bx, y);
      for (int x = 0; x < g.block; ++x, p += image.channels) {
        p[0] = p[1] = p[2] = v;
        if (image.channels == 4) p[3] = 255;
      }
    }
  }
}

std::optional<FrameStamp> read_frame_stamp(const Image& image) {
  if (image.channels < 3 || image.width <= 0 || image.height <= 0) return std::nullopt;
  StampGeometry g;
  g.block = std::max(4, std::min(image.width, image.height) / 64);
  if (image.width < g.width() || image.height < g.height()) return std::nullopt;
  // Average the central half of each block: its edges are where the codec's ringing and the
  // chroma subsampling of neighbouring content land.
  const int lo = g.block / 4, hi = g.block - g.block / 4;
  std::uint64_t payload = 0;
  std::uint16_t crc = 0;
  for (int i = 0; i < kBits; ++i) {
    const int bx = (i % kStampColumns) * g.block, by = (i / kStampColumns) * g.block;
    int sum = 0, n = 0;
    for (int y = by + lo; y < by + hi; ++y) {
      const std::uint8_t* p = image.at(bx + lo, y);
      for (int x = lo; x < hi; ++x, p += image.channels) {
        sum += (77 * p[0] + 150 * p[1] + 29 * p[2]) >> 8;  // BT.601 luma, integer weights
        ++n;
      }
    }
    const int mean = sum / n;
    // A stamp block is black or white; anything in between means "not a stamp" (natural content or
    // destroyed by compression) rather than a guessed bit.
    if (mean > 80 && mean < 176) return std::nullopt;
    const bool bit = mean >= 176;
    if (i < 64)
      payload = (payload << 1) | std::uint64_t(bit);
    else
      crc = std::uint16_t((crc << 1) | std::uint16_t(bit));
  }
  if ((payload >> 60) != kSync || crc16(payload) != crc) return std::nullopt;
  FrameStamp s;
  s.camera = std::uint32_t((payload >> 36) & kStampMaxCamera);
  s.task = std::uint32_t((payload >> 20) & kStampMaxTask);
  s.frame = std::uint32_t(payload & kStampMaxFrame);
  return s;
}

}  // namespace panoptes
