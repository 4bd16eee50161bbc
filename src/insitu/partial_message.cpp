#include "insitu/partial_message.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

#include "core/error.hpp"

namespace panoptes::insitu {

void pack_rows(const render::PartialImage& p, int y0, int y1, std::vector<char>& out) {
  const bool empty = p.rect.empty() || y1 <= y0;
  const std::int32_t head[5] = {p.rect.x0, empty ? p.rect.y0 : y0, p.rect.x1, empty ? p.rect.y1 : y1, p.slivers ? 1 : 0};
  const std::size_t w = std::size_t(std::max(p.rect.width(), 0));
  const std::size_t n = empty ? 0 : w * std::size_t(y1 - y0), first = empty ? 0 : w * std::size_t(y0 - p.rect.y0);
  const std::size_t at = out.size();
  const std::size_t extra = p.slivers ? n * (4 * sizeof(float) + 1) : 0;
  out.resize(at + sizeof head + n * 5 * sizeof(float) + extra);
  char* q = out.data() + at;
  std::memcpy(q, head, sizeof head);
  q += sizeof head;
  if (!n) return;
  std::memcpy(q, p.rgba.data() + 4 * first, n * 4 * sizeof(float));
  std::memcpy(q + n * 4 * sizeof(float), p.depth.data() + first, n * sizeof(float));
  if (!p.slivers) return;
  q += n * 5 * sizeof(float);
  std::memcpy(q, p.rgba_open.data() + 4 * first, n * 4 * sizeof(float));
  std::memcpy(q + n * 4 * sizeof(float), p.sliver_end.data() + first, n);
}

void pack(const render::PartialImage& p, std::vector<char>& out) { pack_rows(p, p.rect.y0, p.rect.y1, out); }

const char* unpack(const char* in, const char* end, int width, int height, render::PartialImage& p) {
  std::int32_t head[5];
  if (end - in < std::ptrdiff_t(sizeof head)) throw Error("in-situ compositing: truncated partial-image message");
  std::memcpy(head, in, sizeof head);
  in += sizeof head;
  p.slivers = head[4] != 0;
  p.reset(width, height, {head[0], head[1], head[2], head[3]});
  const std::size_t n = p.rect.empty() ? 0 : std::size_t(p.rect.width()) * std::size_t(p.rect.height());
  const std::size_t bytes = n * 5 * sizeof(float) + (p.slivers ? n * (4 * sizeof(float) + 1) : 0);
  if (end - in < std::ptrdiff_t(bytes))
    throw Error("in-situ compositing: truncated partial-image message (" + std::to_string(end - in) + " bytes left, " +
                std::to_string(bytes) + " expected for a " + std::to_string(p.rect.width()) + "x" +
                std::to_string(p.rect.height()) + " rect)");
  if (n) {
    std::memcpy(p.rgba.data(), in, n * 4 * sizeof(float));
    std::memcpy(p.depth.data(), in + n * 4 * sizeof(float), n * sizeof(float));
    if (p.slivers) {
      std::memcpy(p.rgba_open.data(), in + n * 5 * sizeof(float), n * 4 * sizeof(float));
      std::memcpy(p.sliver_end.data(), in + n * 9 * sizeof(float), n);
    }
  }
  return in + bytes;
}

}  // namespace panoptes::insitu
