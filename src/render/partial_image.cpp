#include "render/partial_image.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <numeric>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

#include "core/error.hpp"

namespace panoptes::render {

void PartialImage::resize(int w, int h, PixelRect r) {
  width = w;
  height = h;
  r.x0 = std::clamp(r.x0, 0, w);
  r.x1 = std::clamp(r.x1, r.x0, w);
  r.y0 = std::clamp(r.y0, 0, h);
  r.y1 = std::clamp(r.y1, r.y0, h);
  rect = r;
  const std::size_t n = std::size_t(r.width()) * r.height();
  rgba.resize(4 * n);
  depth.resize(n);
  rgba_open.resize(slivers ? 4 * n : 0);
  sliver_end.resize(slivers ? n : 0);
}

void PartialImage::reset(int w, int h, PixelRect r) {
  resize(w, h, r);
  std::fill(rgba.begin(), rgba.end(), 0.0f);
  std::fill(depth.begin(), depth.end(), kNoDepth);
  std::fill(rgba_open.begin(), rgba_open.end(), 0.0f);
  std::fill(sliver_end.begin(), sliver_end.end(), SliverEnd::pass);
}

namespace {
// Resets `out` to the union of the parts' rects (reusing its buffers' capacity).
void union_target(std::span<const PartialImage* const> parts, PartialImage& out) {
  if (parts.empty()) {
    out = PartialImage{};
    return;
  }
  PixelRect u{1 << 30, 1 << 30, -(1 << 30), -(1 << 30)};
  for (const PartialImage* p : parts) {
    if (p->width != parts[0]->width || p->height != parts[0]->height)
      throw Error("composite: partial images of different sizes (" + std::to_string(p->width) + "x" +
                  std::to_string(p->height) + " vs " + std::to_string(parts[0]->width) + "x" +
                  std::to_string(parts[0]->height) + ")");
    if (p->rect.empty()) continue;
    u.x0 = std::min(u.x0, p->rect.x0);
    u.y0 = std::min(u.y0, p->rect.y0);
    u.x1 = std::max(u.x1, p->rect.x1);
    u.y1 = std::max(u.y1, p->rect.y1);
  }
  if (u.empty()) u = {};
  out.slivers = false;
  for (const PartialImage* p : parts) out.slivers = out.slivers || p->slivers;
  out.reset(parts[0]->width, parts[0]->height, u);
}

// Front-to-back join of an anti-aliased isosurface's partials with their sliver state
// (PartialImage::slivers): the composite as a function of the state at its front, with no sliver
// open there (colour acc, state sc) and with one (acc_open, so). A partial adds the colour that
// state calls for and sets the state unless it passes it on. Each partial is such a function of two
// states and this is their composition, so the join is associative (trees and direct send keep
// working) and the composite's acc is what one march through all the bricks gives.
struct SliverChain {
  float* acc;
  float* acc_open;
  SliverEnd sc = SliverEnd::closed, so = SliverEnd::open;
  void add(const PartialImage& p, int x, int y) {
    const float* closed = p.rgba_at(x, y);
    if (!p.slivers) {  // no sliver state (e.g. no anti-aliasing): the same colour for both
      over(acc, closed);
      over(acc_open, closed);
      return;
    }
    const std::size_t i = p.index(x, y);
    const float* open = &p.rgba_open[4 * i];
    over(acc, sc == SliverEnd::open ? open : closed);
    over(acc_open, so == SliverEnd::open ? open : closed);
    if (p.sliver_end[i] != SliverEnd::pass) sc = so = p.sliver_end[i];
  }
  // Two functions of {pass, closed, open} compose to pass or a constant, so so != sc means pass.
  SliverEnd end() const { return sc == so ? sc : SliverEnd::pass; }
};
}  // namespace

void composite_into(Blend blend, std::span<const PartialImage* const> parts, PartialImage& out) {
  union_target(parts, out);
  const int n = int(parts.size());
  const bool over_all = blend == Blend::over;
#pragma omp parallel
  {
    // One sort buffer per thread (parts are few: one per rank with a brick).
    std::vector<std::pair<float, int>> order(std::size_t(n) + 0);
#pragma omp for schedule(static)
    for (int y = out.rect.y0; y < out.rect.y1; ++y) {
      for (int x = out.rect.x0; x < out.rect.x1; ++x) {
        int m = 0;
        for (int i = 0; i < n; ++i) {
          const float d = parts[i]->depth_at(x, y);
          if (d != PartialImage::kNoDepth) order[std::size_t(m++)] = {d, i};
        }
        // Ties keep the lower index first (pairs compare their index too): the same pixel for any
        // order of arrival, which a max blend's equal maxima of different colours would otherwise not be.
        std::sort(order.begin(), order.begin() + m);
        float* acc = out.rgba_at(x, y);
        if (over_all && out.slivers) {
          const std::size_t i = out.index(x, y);
          SliverChain chain{acc, &out.rgba_open[4 * i]};
          for (int r = 0; r < m; ++r) chain.add(*parts[order[std::size_t(r)].second], x, y);
          out.sliver_end[i] = chain.end();
        } else if (over_all) {
          for (int r = 0; r < m; ++r) over(acc, parts[order[std::size_t(r)].second]->rgba_at(x, y));
        } else if (m) {  // max: the partial holding the largest maximum decides alone
          std::copy_n(parts[order[0].second]->rgba_at(x, y), 4, acc);
        }
        out.depth[std::size_t(y - out.rect.y0) * out.rect.width() + (x - out.rect.x0)] =
            m ? order[0].first : PartialImage::kNoDepth;
      }
    }
  }
}

void composite_into(TaskKind kind, std::span<const PartialImage* const> parts, PartialImage& out) {
  composite_into(blend_of(kind), parts, out);
}

PartialImage composite(TaskKind kind, std::span<const PartialImage* const> parts) {
  PartialImage out;
  composite_into(kind, parts, out);
  return out;
}

PartialImage composite_ordered(TaskKind kind, std::span<const PartialImage* const> parts) {
  if (blend_of(kind) != Blend::over) return composite(kind, parts);  // a maximum has no order
  PartialImage out;
  union_target(parts, out);
#pragma omp parallel for schedule(static)
  for (int y = out.rect.y0; y < out.rect.y1; ++y)
    for (int x = out.rect.x0; x < out.rect.x1; ++x) {
      float* acc = out.rgba_at(x, y);
      float dmin = PartialImage::kNoDepth;
      const std::size_t i = out.index(x, y);
      SliverChain chain{acc, out.slivers ? &out.rgba_open[4 * i] : nullptr};
      for (const PartialImage* p : parts) {
        if (!p->rect.contains(x, y)) continue;
        if (out.slivers) {
          if (p->depth_at(x, y) != PartialImage::kNoDepth) chain.add(*p, x, y);  // a miss has no event
        } else {
          over(acc, p->rgba_at(x, y));
        }
        dmin = std::min(dmin, p->depth_at(x, y));
      }
      if (out.slivers) out.sliver_end[i] = chain.end();
      out.depth[std::size_t(y - out.rect.y0) * out.rect.width() + (x - out.rect.x0)] = dmin;
    }
  return out;
}

std::vector<int> visibility_order(const camera::Camera& cam, const GridGeometry& g, std::span<const Brick> bricks) {
  std::vector<double> key(bricks.size());
  for (std::size_t i = 0; i < bricks.size(); ++i) {
    double k = 0;
    for (int a = 0; a < 3; ++a) {
      const double lo = g.origin[a] + bricks[i].lo[a] * g.spacing[a];
      const double hi = g.origin[a] + bricks[i].hi[a] * g.spacing[a];
      const double c = cam.position()[a];
      k += c < lo ? lo - c : (c > hi ? c - hi : 0.0);
    }
    key[i] = k;
  }
  // A camera on a face shared by bricks is at distance 0 from all of them; the one that owns the eye
  // by the march's rule (half-open [lo, hi), closed at the domain's upper faces) holds every ray's t = 0
  // sample and must come first; any other ray crosses only one of the rest.
  std::vector<char> owns(bricks.size());
  for (std::size_t i = 0; i < bricks.size(); ++i) {
    bool in = true;
    for (int a = 0; a < 3; ++a) {
      const double p = (cam.position()[a] - g.origin[a]) / g.spacing[a];
      const double lo = bricks[i].lo[a], hi = bricks[i].hi[a];
      in = in && p >= lo && (p < hi || (p == hi && hi == g.dims[a] - 1));
    }
    owns[i] = in;
  }
  std::vector<int> order(bricks.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const auto ia = std::size_t(a), ib = std::size_t(b);
    return key[ia] != key[ib] ? key[ia] < key[ib] : owns[ia] > owns[ib];
  });
  return order;
}

namespace {
// The outline's coverage of the image, kept sparse: a segment of width 1.5 touches a few thousand
// pixels of an image of a quarter million, so finish_image() composites every pixel without it and
// then redoes only the touched ones. The dense buffers live per calling thread and are cleared
// through the touched lists, so a warm call neither allocates nor writes the whole image twice.
// The coverage depends on the camera, the domain and the width only, so it is kept for the next
// call: the in-situ session finishes K images of one camera in a row (the demo: 3), and drawing the 12
// edges was about half of finish_image's time there (perf, BM_Run/demo, 2026-11-25).
struct OutlineCoverage {
  struct Key {
    Vec3 position, forward, right, up, lo, hi;
    double fov = 0, width = 0;
    int w = 0, h = 0;
    camera::Projection projection = camera::Projection::perspective;
    bool box = true, compass = false;  // the compass: equirectangular frames only
    Vec3 north, east, sky;    // the compass's frame (zero without one)
    bool operator==(const Key&) const = default;
  };
  std::vector<float> front, back;                  // w×h coverage in [0, 1], zero where untouched
  std::vector<std::uint32_t> touched;              // indices whose front or back coverage is > 0
  Key key;                                         // what front and back were drawn for
  bool drawn = false;
  void prepare(std::size_t n) {
    if (front.size() < n) {
      front.assign(n, 0.0f);
      back.assign(n, 0.0f);
    }
  }
  void clear() {
    for (const std::uint32_t i : touched) front[i] = back[i] = 0.0f;
    touched.clear();
    drawn = false;
  }
};

// Anti-aliased segment coverage into a w×h float buffer (max of coverages); records every pixel the
// buffer turns non-zero in `touched` (each at most once per buffer).
void draw_segment(std::vector<float>& buf, std::vector<std::uint32_t>& touched, int w, int h, double ax, double ay,
                  double bx, double by, double width, float strength = 1.0f) {
  const double half = 0.5 * width;
  const double x0 = std::min(ax, bx) - half - 1, x1 = std::max(ax, bx) + half + 1;
  const double y0 = std::min(ay, by) - half - 1, y1 = std::max(ay, by) + half + 1;
  const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
  const bool steep = std::abs(dy) > std::abs(dx);
  // Walk the major axis; on each step visit only the pixels within half+1 of the line.
  const int m0 = int(std::floor(std::max(steep ? y0 : x0, 0.0)));
  const int m1 = int(std::ceil(std::min(steep ? y1 : x1, double(steep ? h : w) - 1)));
  for (int m = m0; m <= m1; ++m) {
    const double mc = m + 0.5;
    double nc;  // minor coordinate of the line at this major coordinate
    if (steep) nc = std::abs(dy) > 0 ? ax + dx * (mc - ay) / dy : ax;
    else nc = std::abs(dx) > 0 ? ay + dy * (mc - ax) / dx : ay;
    const int n0 = std::max(0, int(std::floor(nc - half - 1.5)));
    const int n1 = std::min((steep ? w : h) - 1, int(std::ceil(nc + half + 1.5)));
    for (int n = n0; n <= n1; ++n) {
      const double px = steep ? n + 0.5 : mc, py = steep ? mc : n + 0.5;
      double t = len2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0;
      t = std::clamp(t, 0.0, 1.0);
      const double ex = px - (ax + t * dx), ey = py - (ay + t * dy);
      const double cov = strength * std::clamp(half + 0.5 - std::sqrt(ex * ex + ey * ey), 0.0, 1.0);
      const std::size_t i = std::size_t(steep ? m : n) * w + (steep ? n : m);
      float& b = buf[i];
      if (b == 0.0f && float(cov) > 0.0f) touched.push_back(std::uint32_t(i));
      b = std::max(b, float(cov));
    }
  }
}

// Projects the segment a–b after clipping it to the half-space in front of the camera.
bool project_segment(const camera::Camera& cam, Vec3 a, Vec3 b, double& ax, double& ay, double& bx, double& by) {
  const double near = 1e-6 * (1 + norm(cam.look_at() - cam.position()));
  const double za = dot(a - cam.position(), cam.forward()), zb = dot(b - cam.position(), cam.forward());
  if (za < near && zb < near) return false;
  if (za < near) a = a + (b - a) * ((near - za) / (zb - za));
  if (zb < near) b = b + (a - b) * ((near - zb) / (za - zb));
  return cam.project(a, ax, ay) && cam.project(b, bx, by);
}

// The segment a–b of world space in an equirectangular frame: the arc of the great circle through the
// camera it projects to. Halved until a piece spans at most 4 pixels (or 14 halvings: a piece through a
// pole); a piece whose ends lie more than half the width apart crosses the left/right seam and is drawn
// twice, once leaving each side of the frame.
void draw_arc(std::vector<float>& buf, std::vector<std::uint32_t>& touched, const camera::Camera& cam, const Vec3& a,
              double ax, double ay, const Vec3& b, double bx, double by, double width, float strength, int depth = 0) {
  const int w = cam.width(), h = cam.height();
  double dx = bx - ax;
  const bool wraps = std::abs(dx) > 0.5 * w;
  if (wraps) dx -= std::copysign(double(w), dx);
  if (depth >= 14 || dx * dx + (by - ay) * (by - ay) <= 16) {
    if (!wraps) {
      draw_segment(buf, touched, w, h, ax, ay, bx, by, width, strength);
    } else {
      draw_segment(buf, touched, w, h, ax, ay, ax + dx, by, width, strength);
      draw_segment(buf, touched, w, h, bx - dx, ay, bx, by, width, strength);
    }
    return;
  }
  const Vec3 m = (a + b) * 0.5;
  double mx, my;
  if (!cam.project(m, mx, my)) return;  // the camera lies on the segment: nothing to see of it
  draw_arc(buf, touched, cam, a, ax, ay, m, mx, my, width, strength, depth + 1);
  draw_arc(buf, touched, cam, m, mx, my, b, bx, by, width, strength, depth + 1);
}

// draw_arc() of the world segment a–b.
void draw_world_arc(std::vector<float>& buf, std::vector<std::uint32_t>& touched, const camera::Camera& cam,
                    const Vec3& a, const Vec3& b, double width, float strength) {
  double ax, ay, bx, by;
  if (cam.project(a, ax, ay) && cam.project(b, bx, by))
    draw_arc(buf, touched, cam, a, ax, ay, b, bx, by, width, strength);
}

// A 5×7 bitmap letter (rows top to bottom, bit 4 = leftmost column) centred at column cx with its bottom
// row ending at row by, each bitmap cell `scale` pixels square; columns wrap around the 360° frame.
void draw_glyph(std::vector<float>& buf, std::vector<std::uint32_t>& touched, int w, int h, char letter, double cx,
                double by, int scale, float strength) {
  static constexpr std::array<std::array<std::uint8_t, 7>, 4> kGlyphs{{
      {0b10001, 0b11001, 0b11001, 0b10101, 0b10011, 0b10011, 0b10001},  // N
      {0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b11111},  // E
      {0b01111, 0b10000, 0b10000, 0b01110, 0b00001, 0b00001, 0b11110},  // S
      {0b10001, 0b10001, 0b10001, 0b10101, 0b10101, 0b10101, 0b01010},  // W
  }};
  const std::size_t g = letter == 'N' ? 0 : letter == 'E' ? 1 : letter == 'S' ? 2 : 3;
  const int x0 = int(std::lround(cx - 2.5 * scale)), y0 = int(std::lround(by)) - 7 * scale;
  for (int r = 0; r < 7 * scale; ++r) {
    const int y = y0 + r;
    if (y < 0 || y >= h) continue;
    for (int c = 0; c < 5 * scale; ++c) {
      if (!(kGlyphs[g][std::size_t(r / scale)] >> (4 - c / scale) & 1)) continue;
      const int x = ((x0 + c) % w + w) % w;
      const std::size_t i = std::size_t(y) * w + x;
      if (buf[i] == 0.0f) touched.push_back(std::uint32_t(i));
      buf[i] = std::max(buf[i], strength);
    }
  }
}

// The compass of an equirectangular frame into `buf`: the horizon of `sky` (eight 45° arcs, faint), a
// tick across it every 45° (the cardinal ones longer) and N/E/S/W above the cardinal ticks. Sizes
// follow the frame's height, so a mark covers the same angle at every resolution.
void draw_compass(std::vector<float>& buf, std::vector<std::uint32_t>& touched, const camera::Camera& cam,
                  const camera::SkyFrame& sky, double width) {
  const int w = cam.width(), h = cam.height();
  const Vec3 c = cam.position();
  const double deg = std::numbers::pi / 180;
  auto dir = [&](double azimuth_deg, double elevation_deg) {  // azimuth from north towards east
    const double az = azimuth_deg * deg, el = elevation_deg * deg;
    return (sky.north * std::cos(az) + sky.east * std::sin(az)) * std::cos(el) + sky.sky * std::sin(el);
  };
  for (int k = 0; k < 8; ++k) draw_world_arc(buf, touched, cam, c + dir(45.0 * k, 0), c + dir(45.0 * (k + 1), 0), width, 0.35f);
  const int scale = std::max(1, int(std::lround(h / 240.0)));
  for (int k = 0; k < 8; ++k) {
    const bool cardinal = k % 2 == 0;
    const double len = cardinal ? 2.5 : 1.2;  // degrees above and below the horizon
    draw_world_arc(buf, touched, cam, c + dir(45.0 * k, -len), c + dir(45.0 * k, len), width, cardinal ? 0.7f : 0.5f);
    double px, py;
    if (!cardinal || !cam.project(c + dir(45.0 * k, len + 1.0), px, py)) continue;
    draw_glyph(buf, touched, w, h, "NESW"[k / 2], px, py, scale, 0.8f);
  }
}

// Redraws `cover` for the camera, the domain box lo–hi and the line width that `key` names.
void draw_outline(const camera::Camera& cam, const Vec3& lo, const Vec3& hi, double width,
                  const OutlineCoverage::Key& key, const camera::SkyFrame& sky, OutlineCoverage& cover) {
  const int w = cam.width(), h = cam.height();
  const Vec3 c = cam.position();
  cover.clear();
  cover.prepare(std::size_t(w) * h);
  // Face (axis a, side s) is turned towards the camera when the camera is beyond its plane.
  auto facing = [&](int a, int s) { return s ? c[a] > hi[a] : c[a] < lo[a]; };
  for (int a = 0; a < (key.box ? 3 : 0); ++a) {
    const int b = (a + 1) % 3, d = (a + 2) % 3;
    for (int sb = 0; sb < 2; ++sb)
      for (int sd = 0; sd < 2; ++sd) {
        Vec3 p = lo, q = lo;
        p[b] = q[b] = sb ? hi[b] : lo[b];
        p[d] = q[d] = sd ? hi[d] : lo[d];
        q[a] = hi[a];
        const bool is_front = facing(b, sb) || facing(d, sd);
        if (cam.projection() == camera::Projection::equirectangular) {
          draw_world_arc(is_front ? cover.front : cover.back, cover.touched, cam, p, q, width, 1.0f);
          continue;
        }
        double ax, ay, bx, by;
        if (!project_segment(cam, p, q, ax, ay, bx, by)) continue;
        draw_segment(is_front ? cover.front : cover.back, cover.touched, w, h, ax, ay, bx, by, width);
      }
  }
  if (key.compass) draw_compass(cover.back, cover.touched, cam, sky, width);
  cover.key = key;
  cover.drawn = true;
}

// A colour in [0, 1] (NaN counts as 0) to 8 bits, rounding half away from zero: exactly
// std::lround(v * 255) for every float v, since v * 255 is computed in float as before and a float
// plus 0.5 is exact in double. Inline, so the pixel loop vectorizes (lroundf is a libm call).
inline std::uint8_t to_byte(float c) {
  const float v = (c > 0.0f ? std::min(c, 1.0f) : 0.0f) * 255.0f;
  return std::uint8_t(int(double(v) + 0.5));
}

// One row of premultiplied RGBA over the background `bgc` to RGBA8 (alpha 255): to_byte(v[k] + (1 − v[3])·bgc[k]).
void finish_row(const float* v, std::uint8_t* q, int n, const float bgc[3]) {
  int x = 0;
#if defined(__AVX2__) && defined(__FMA__)
  // A pixel's four channels at once. The scalar loop compiled with FMA contracts v + (1 − α)·bg into
  // one fused multiply-add, so this does too; the clamp sends NaN to 0 as to_byte does (the comparison
  // is false for NaN); the alpha lane's byte is overwritten with 255. The same bytes as the scalar
  // loop, at about a third of its instructions (no branches, one conversion for four channels).
  const __m128 bg = _mm_setr_ps(bgc[0], bgc[1], bgc[2], 0.0f), one = _mm_set1_ps(1.0f), zero = _mm_setzero_ps();
  const __m128 scale = _mm_set1_ps(255.0f);
  const __m256d half = _mm256_set1_pd(0.5);
  const __m128i opaque = _mm_set1_epi32(int(0xff000000u));
  for (; x < n; ++x, v += 4, q += 4) {
    const __m128 p = _mm_loadu_ps(v);
    const __m128 c = _mm_fmadd_ps(_mm_sub_ps(one, _mm_shuffle_ps(p, p, 0xff)), bg, p);
    const __m128 t = _mm_mul_ps(_mm_and_ps(_mm_cmpgt_ps(c, zero), _mm_min_ps(c, one)), scale);
    const __m128i i = _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_cvtps_pd(t), half));
    const __m128i b = _mm_packus_epi16(_mm_packus_epi32(i, i), _mm_setzero_si128());
    const int rgba = _mm_cvtsi128_si32(_mm_or_si128(b, opaque));
    std::memcpy(q, &rgba, 4);
  }
#endif
  for (; x < n; ++x, v += 4, q += 4) {
    q[0] = to_byte(v[0] + (1 - v[3]) * bgc[0]);
    q[1] = to_byte(v[1] + (1 - v[3]) * bgc[1]);
    q[2] = to_byte(v[2] + (1 - v[3]) * bgc[2]);
    q[3] = 255;
  }
}
}  // namespace

void finish_image_into(const PartialImage& comp, const camera::Camera& cam, const GridGeometry& g, Image& img, Rgb bg,
                       const OutlineStyle& outline) {
  const int w = cam.width(), h = cam.height();
  if (comp.width != w || comp.height != h)
    throw Error("finish_image: partial image is " + std::to_string(comp.width) + "x" + std::to_string(comp.height) +
                " but the camera's image is " + std::to_string(w) + "x" + std::to_string(h));
  if (img.width != w || img.height != h || img.channels != 4) img = Image(w, h, 4);
  const float lc[3] = {outline.colour.r, outline.colour.g, outline.colour.b};
  const float bgc[3] = {bg.r, bg.g, bg.b};
  // Every pixel without the outline: the background, under the composited volume inside its rect.
  const std::uint8_t bg8[4] = {to_byte(bgc[0]), to_byte(bgc[1]), to_byte(bgc[2]), 255};
  const PixelRect& r = comp.rect;
#pragma omp parallel for schedule(static)
  for (int y = 0; y < h; ++y) {
    std::uint8_t* o = img.row(y);
    const bool in_rows = y >= r.y0 && y < r.y1;
    const int xa = in_rows ? r.x0 : w, xb = in_rows ? r.x1 : w;
    for (int x = 0; x < xa; ++x) std::memcpy(o + 4 * std::size_t(x), bg8, 4);
    if (xa < xb) finish_row(comp.rgba_at(xa, y), o + 4 * std::size_t(xa), xb - xa, bgc);
    for (int x = std::max(xb, 0); x < w; ++x) std::memcpy(o + 4 * std::size_t(x), bg8, 4);
  }
  if (!outline.enabled) return;

  thread_local OutlineCoverage cover;
  const Vec3 lo = g.domain_lo(), hi = g.domain_hi();
  const bool compass = outline.compass && cam.projection() == camera::Projection::equirectangular;
  const OutlineCoverage::Key key{cam.position(), cam.forward(), cam.right(), cam.up(), lo, hi,
                                 cam.fov_y_degrees(), outline.width, w, h, cam.projection(), outline.box, compass,
                                 compass ? outline.sky.north : Vec3{}, compass ? outline.sky.east : Vec3{},
                                 compass ? outline.sky.sky : Vec3{}};
  if (!cover.drawn || !(cover.key == key)) draw_outline(cam, lo, hi, outline.width, key, outline.sky, cover);
  // The touched pixels again, with the outline behind and in front of the volume. A pixel touched
  // by both buffers is listed twice and computed twice to the same value.
  for (const std::uint32_t i : cover.touched) {
    const int x = int(i % std::uint32_t(w)), y = int(i / std::uint32_t(w));
    const float fb = cover.back[i], ff = cover.front[i];
    float col[3] = {bgc[0], bgc[1], bgc[2]};
    if (fb > 0)
      for (int k = 0; k < 3; ++k) col[k] = fb * lc[k] + (1 - fb) * col[k];
    if (r.contains(x, y)) {
      const float* v = comp.rgba_at(x, y);
      for (int k = 0; k < 3; ++k) col[k] = v[k] + (1 - v[3]) * col[k];
    }
    if (ff > 0)
      for (int k = 0; k < 3; ++k) col[k] = ff * lc[k] + (1 - ff) * col[k];
    std::uint8_t* o = img.at(x, y);
    for (int k = 0; k < 3; ++k) o[k] = to_byte(col[k]);
  }
}

Image finish_image(const PartialImage& comp, const camera::Camera& cam, const GridGeometry& g, Rgb bg,
                   const OutlineStyle& outline) {
  Image img;
  finish_image_into(comp, cam, g, img, bg, outline);
  return img;
}

}  // namespace panoptes::render
