#include "video/movie_test_util.hpp"

#include <algorithm>
#include <cmath>

#include "core/frame_stamp.hpp"

namespace panoptes::video::testing {

Image make_test_frame(int width, int height, int index, int channels) {
  Image img(width, height, channels);
  const double t = index * 0.15;
  // A shaded sphere and a ring moving on circles, over a smooth colour field: roughly what a volume
  // rendering of a wave field looks like (large smooth areas, some sharp silhouettes).
  const double sx = width * (0.5 + 0.25 * std::cos(t)), sy = height * (0.5 + 0.25 * std::sin(t));
  const double sr = std::min(width, height) * 0.18;
  const double rx = width * (0.5 + 0.3 * std::cos(-1.3 * t + 1)), ry = height * (0.5 + 0.3 * std::sin(-1.3 * t + 1));
  const double r0 = std::min(width, height) * 0.12, r1 = r0 * 0.6;
  for (int y = 0; y < height; ++y) {
    std::uint8_t* row = img.row(y);
    const double v = double(y) / height;
    for (int x = 0; x < width; ++x) {
      const double u = double(x) / width;
      double r = 40 + 60 * u + 30 * std::sin(6.0 * v + t);
      double g = 30 + 80 * v + 25 * std::sin(5.0 * u - 0.7 * t);
      double b = 90 + 70 * (1 - u) * v + 20 * std::cos(4.0 * (u + v) + t);
      // Silhouettes are anti-aliased over about one pixel, as a ray caster's are.
      const double dx = x - sx, dy = y - sy, d = std::sqrt(dx * dx + dy * dy);
      const double cover = std::clamp(sr - d + 0.5, 0.0, 1.0);
      if (cover > 0) {  // Lambert-shaded sphere, light from the upper left
        const double nz = std::sqrt(std::max(0.0, 1 - (d * d) / (sr * sr)));
        const double shade = std::max(0.0, (-dx / sr) * -0.4 + (-dy / sr) * -0.4 + nz * 0.8);
        r = (1 - cover) * r + cover * (220 * shade + 20);
        g = (1 - cover) * g + cover * (140 * shade + 15);
        b = (1 - cover) * b + cover * (60 * shade + 10);
      }
      const double ex = x - rx, ey = y - ry, e = std::sqrt(ex * ex + ey * ey);
      const double a = 0.7 * std::clamp(r0 - e + 0.5, 0.0, 1.0) * std::clamp(e - r1 + 0.5, 0.0, 1.0);
      if (a > 0) {  // a semi-transparent ring
        r = (1 - a) * r + a * 40;
        g = (1 - a) * g + a * 200;
        b = (1 - a) * b + a * 230;
      }
      std::uint8_t* p = row + std::size_t(x) * channels;
      p[0] = std::uint8_t(std::clamp(r, 0.0, 255.0));
      p[1] = std::uint8_t(std::clamp(g, 0.0, 255.0));
      p[2] = std::uint8_t(std::clamp(b, 0.0, 255.0));
      if (channels == 4) p[3] = 255;
    }
  }
  if (width >= 40 && height >= 32) draw_frame_stamp(img, FrameStamp{0, 0, std::uint32_t(index)});
  return img;
}

int read_test_frame_number(const Image& image) {
  const auto stamp = read_frame_stamp(image);
  return stamp ? int(stamp->frame) : -1;
}

}  // namespace panoptes::video::testing
