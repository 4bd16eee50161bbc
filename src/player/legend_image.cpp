#include "player/legend_image.hpp"

#include <stb/stb_easy_font.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "player/legend.hpp"

namespace panoptes::player {
namespace {

using PanelColour = std::array<float, 3>;

// Blends `c` with opacity `a` over the pixels of [x0, x1) x [y0, y1), clipped to the image.
void blend_rect(Image& im, int x0, int y0, int x1, int y1, PanelColour c, float a = 1) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, im.width), y1 = std::min(y1, im.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      std::uint8_t* p = im.at(x, y);
      for (int k = 0; k < 3; ++k) p[k] = std::uint8_t(std::lround(p[k] * (1 - a) + std::clamp(c[std::size_t(k)], 0.f, 1.f) * 255 * a));
    }
}

struct BitmapText {
  int scale = 1;
  // Width and height of `s` in image pixels.
  int width(const std::string& s) const { return stb_easy_font_width(const_cast<char*>(s.c_str())) * scale; }
  int height() const { return 7 * scale; }
  // Draws `s` with its top-left corner at (x, y).
  void draw(Image& im, int x, int y, const std::string& s, PanelColour c) const {
    static thread_local std::vector<char> buf(1 << 16);
    const int quads = stb_easy_font_print(0, 0, const_cast<char*>(s.c_str()), nullptr, buf.data(), int(buf.size()));
    // Each quad: 4 vertices of (x, y, z: float, rgba: 4 bytes); axis-aligned rectangles.
    for (int q = 0; q < quads; ++q) {
      const float* v0 = reinterpret_cast<const float*>(buf.data() + std::size_t(q) * 64);
      const float* v2 = reinterpret_cast<const float*>(buf.data() + std::size_t(q) * 64 + 32);
      blend_rect(im, x + int(v0[0]) * scale, y + int(v0[1]) * scale, x + int(v2[0]) * scale, y + int(v2[1]) * scale, c);
    }
  }
};

const PanelColour kPanelText{0.90f, 0.91f, 0.94f}, kPanelDim{0.62f, 0.66f, 0.74f}, kPanelAmber{1.0f, 0.78f, 0.30f}, kPanelFrame{0.55f, 0.6f, 0.7f};

}  // namespace

int draw_legend(Image& im, const store::Manifest& m, int task, int frame) {
  const std::vector<LegendBar> bars = task_legend(m, task, frame);
  if (bars.empty() || im.width < 64 || im.height < 64) return 0;
  const BitmapText t{im.height >= 600 ? 2 : 1};
  const int pad = 4 * t.scale, line = t.height() + 3 * t.scale, bar_h = 8 * t.scale;
  const int bar_w = std::clamp(im.width / 4, 80, 130 * t.scale);
  struct Row {
    std::string title, lo, hi, scale, change;  // change: "x2.9 since the previous frame", in amber
  };
  std::vector<Row> rows;
  int width = bar_w;
  for (const LegendBar& b : bars) {
    Row r;
    // The bitmap font draws '|' like 'l' ("lphi_pl"): name the absolute value in words.
    std::string label = b.label;
    if (label.size() > 2 && label.front() == '|' && label.back() == '|') label = "abs " + label.substr(1, label.size() - 2);
    r.title = label + (b.physical && !b.units.empty() ? "  [" + b.units + "]" : "");
    if (b.isovalue) r.title += "  " + legend_range_text(b);
    r.lo = legend_number(b.lo);
    r.hi = legend_number(b.hi) + (b.physical ? "" : " x ref");
    std::string other;
    for (const LegendBar& o : bars)
      if (&o != &b) other = o.field;
    const std::string mode = legend_scale_mode_text(b, other);
    if (!mode.empty()) r.scale = "scale: " + mode;
    r.change = legend_change_text(b);
    width = std::max({width, t.width(r.title), t.width(r.scale), t.width(r.change)});
    rows.push_back(std::move(r));
  }
  int height = pad;
  for (std::size_t i = 0; i < bars.size(); ++i)
    height += line + (bars[i].isovalue ? 0 : bar_h + 2 * t.scale + line) + (rows[i].scale.empty() ? 0 : line) +
              (rows[i].change.empty() ? 0 : line) + pad;
  width = std::min(width + 2 * pad, im.width);
  const int x0 = 0, y0 = std::max(0, im.height - height);
  blend_rect(im, x0, y0, x0 + width, im.height, {0.05f, 0.06f, 0.08f}, 0.6f);
  int y = y0 + pad;
  for (std::size_t i = 0; i < bars.size(); ++i) {
    const LegendBar& b = bars[i];
    const Row& r = rows[i];
    const int x = x0 + pad;
    if (b.isovalue) {
      const PanelColour c = b.colours.empty() ? PanelColour{0.8f, 0.8f, 0.8f} : b.colours[0];
      blend_rect(im, x, y, x + t.height(), y + t.height(), c);
      t.draw(im, x + t.height() + 2 * t.scale, y, r.title, kPanelText);
      y += line;
    } else {
      t.draw(im, x, y, r.title, kPanelText);
      y += line;
      const int n = int(b.colours.size());
      if (n >= 2) {
        for (int px = 0; px < bar_w; ++px) {
          const float u = float(px) / float(bar_w - 1) * float(n - 1);
          const int k = std::min(int(u), n - 2);
          const float w = u - float(k);
          PanelColour c;
          for (std::size_t ch = 0; ch < 3; ++ch)
            c[ch] = b.colours[std::size_t(k)][ch] * (1 - w) + b.colours[std::size_t(k + 1)][ch] * w;
          blend_rect(im, x + px, y, x + px + 1, y + bar_h, c);
        }
        blend_rect(im, x, y, x + bar_w, y + 1, kPanelFrame);
        blend_rect(im, x, y + bar_h - 1, x + bar_w, y + bar_h, kPanelFrame);
      }
      y += bar_h + 2 * t.scale;
      t.draw(im, x, y, r.lo, kPanelText);
      t.draw(im, x + std::max(t.width(r.lo) + 6 * t.scale, bar_w - t.width(r.hi)), y, r.hi, kPanelText);
      y += line;
    }
    if (!r.scale.empty()) {
      t.draw(im, x, y, r.scale, kPanelDim);
      y += line;
    }
    if (!r.change.empty()) {
      t.draw(im, x, y, r.change, kPanelAmber);
      y += line;
    }
    y += pad;
  }
  return height;
}

}  // namespace panoptes::player
