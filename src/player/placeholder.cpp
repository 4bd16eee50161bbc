// The placeholder shown instead of a missing or unreadable stream: a dark red frame with a border and
// large block-letter text, so nobody mistakes it for data. Drawn with a built-in 5x7 font (no font
// files needed, works headless), converted to YUV 4:2:0 like decoded frames.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "player/engine.hpp"

namespace panoptes::player {
namespace {

// Rows top to bottom, bit 4 = leftmost column.
std::array<std::uint8_t, 7> glyph(char c) {
  switch (std::toupper(static_cast<unsigned char>(c))) {
    case 'A': return {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11};
    case 'B': return {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E};
    case 'C': return {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E};
    case 'D': return {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C};
    case 'E': return {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F};
    case 'F': return {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10};
    case 'G': return {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F};
    case 'H': return {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11};
    case 'I': return {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E};
    case 'J': return {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C};
    case 'K': return {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11};
    case 'L': return {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F};
    case 'M': return {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11};
    case 'N': return {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11};
    case 'O': return {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E};
    case 'P': return {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10};
    case 'Q': return {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D};
    case 'R': return {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11};
    case 'S': return {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E};
    case 'T': return {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04};
    case 'U': return {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E};
    case 'V': return {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04};
    case 'W': return {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A};
    case 'X': return {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11};
    case 'Y': return {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04};
    case 'Z': return {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F};
    case '0': return {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E};
    case '1': return {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E};
    case '2': return {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F};
    case '3': return {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E};
    case '4': return {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02};
    case '5': return {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E};
    case '6': return {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E};
    case '7': return {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08};
    case '8': return {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E};
    case '9': return {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C};
    case ':': return {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00};
    case '-': return {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00};
    case '.': return {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C};
    case '/': return {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00};
    case '_': return {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F};
    case '?': return {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04};
    default: return {0, 0, 0, 0, 0, 0, 0};
  }
}

void fill_rect(Image& im, int x0, int y0, int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  const int x1 = std::min(im.width, x0 + w), y1 = std::min(im.height, y0 + h);
  for (int y = std::max(0, y0); y < y1; ++y)
    for (int x = std::max(0, x0); x < x1; ++x) {
      std::uint8_t* p = im.at(x, y);
      p[0] = r, p[1] = g, p[2] = b;
    }
}

// Splits text into lines of at most max_chars characters, breaking at spaces where possible.
std::vector<std::string> wrap(std::string_view text, int max_chars) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t i = 0;
  while (i < text.size()) {
    std::size_t j = text.find(' ', i);
    if (j == std::string_view::npos) j = text.size();
    std::string word(text.substr(i, j - i));
    i = j + 1;
    if (!line.empty() && int(line.size() + 1 + word.size()) > max_chars) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

// Draws text centred horizontally with its top at y, glyph cells of 6x8 units of `scale` pixels.
// Returns the y below the text.
int draw_text(Image& im, std::string_view text, int y, int max_scale) {
  const int usable = std::max(6, im.width - 8);
  int scale = std::max(1, std::min(max_scale, usable / std::max<int>(1, int(text.size()) * 6)));
  const auto lines = wrap(text, std::max(1, usable / (6 * scale)));
  for (const auto& line : lines) {
    const int x0 = (im.width - int(line.size()) * 6 * scale + scale) / 2;
    for (std::size_t k = 0; k < line.size(); ++k) {
      const auto g = glyph(line[k]);
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col)
          if (g[std::size_t(row)] & (0x10 >> col))
            fill_rect(im, x0 + (int(k) * 6 + col) * scale, y + row * scale, scale, scale, 255, 255, 255);
    }
    y += 8 * scale;
  }
  return y;
}

}  // namespace

video::YuvFrame make_placeholder(int width, int height, std::string_view title, std::string_view detail) {
  Image im(width, height, 3);
  fill_rect(im, 0, 0, width, height, 96, 0, 0);
  // A yellow border and diagonal hatching in the corners: clearly not a rendering.
  const int border = std::max(1, std::min(width, height) / 40);
  fill_rect(im, 0, 0, width, border, 230, 200, 0);
  fill_rect(im, 0, height - border, width, border, 230, 200, 0);
  fill_rect(im, 0, 0, border, height, 230, 200, 0);
  fill_rect(im, width - border, 0, border, height, 230, 200, 0);
  const int title_scale = std::max(1, std::min(width, height) / 60);
  const int title_height = 8 * title_scale * 2;
  int y = std::max(border + 1, height / 2 - title_height);
  y = draw_text(im, title, y, title_scale);
  draw_text(im, detail, y + title_scale * 4, std::max(1, title_scale / 2));

  video::YuvFrame f;
  f.width = width;
  f.height = height;
  const int cw = (width + 1) / 2, ch = (height + 1) / 2;
  f.y.resize(std::size_t(width) * height);
  f.u.resize(std::size_t(cw) * ch);
  f.v.resize(std::size_t(cw) * ch);
  // BT.601 limited range, as the movies are written.
  for (int yy = 0; yy < height; ++yy)
    for (int x = 0; x < width; ++x) {
      const std::uint8_t* p = im.at(x, yy);
      f.y[std::size_t(yy) * width + x] = std::uint8_t(((66 * p[0] + 129 * p[1] + 25 * p[2] + 128) >> 8) + 16);
    }
  for (int cy = 0; cy < ch; ++cy)
    for (int cx = 0; cx < cw; ++cx) {
      int r = 0, g = 0, b = 0, n = 0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const int x = 2 * cx + dx, yy = 2 * cy + dy;
          if (x >= width || yy >= height) continue;
          const std::uint8_t* p = im.at(x, yy);
          r += p[0], g += p[1], b += p[2], ++n;
        }
      r /= n, g /= n, b /= n;
      f.u[std::size_t(cy) * cw + cx] = std::uint8_t(((-38 * r - 74 * g + 112 * b + 128) >> 8) + 128);
      f.v[std::size_t(cy) * cw + cx] = std::uint8_t(((112 * r - 94 * g - 18 * b + 128) >> 8) + 128);
    }
  return f;
}

}  // namespace panoptes::player
