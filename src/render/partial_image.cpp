#include "render/partial_image.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "core/error.hpp"

namespace panoptes::render {

void PartialImage::reset(int w, int h, PixelRect r) {
  width = w;
  height = h;
  r.x0 = std::clamp(r.x0, 0, w);
  r.x1 = std::clamp(r.x1, r.x0, w);
  r.y0 = std::clamp(r.y0, 0, h);
  r.y1 = std::clamp(r.y1, r.y0, h);
  rect = r;
  const std::size_t n = std::size_t(r.width()) * r.height();
  rgba.assign(4 * n, 0.0f);
  depth.assign(n, kNoDepth);
}

namespace {
PartialImage union_target(std::span<const PartialImage* const> parts) {
  PartialImage out;
  if (parts.empty()) return out;
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
  out.reset(parts[0]->width, parts[0]->height, u);
  return out;
}
}  // namespace

PartialImage composite(std::span<const PartialImage* const> parts) {
  PartialImage out = union_target(parts);
  const int n = int(parts.size());
#pragma omp parallel for schedule(static)
  for (int y = out.rect.y0; y < out.rect.y1; ++y) {
    std::vector<std::pair<float, int>> order(std::size_t(n) + 0);
    for (int x = out.rect.x0; x < out.rect.x1; ++x) {
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const float d = parts[i]->depth_at(x, y);
        if (d != PartialImage::kNoDepth) order[std::size_t(m++)] = {d, i};
      }
      std::sort(order.begin(), order.begin() + m);
      float* acc = out.rgba_at(x, y);
      for (int r = 0; r < m; ++r) over(acc, parts[order[std::size_t(r)].second]->rgba_at(x, y));
      out.depth[std::size_t(y - out.rect.y0) * out.rect.width() + (x - out.rect.x0)] = m ? order[0].first : PartialImage::kNoDepth;
    }
  }
  return out;
}

PartialImage composite_ordered(std::span<const PartialImage* const> parts) {
  PartialImage out = union_target(parts);
#pragma omp parallel for schedule(static)
  for (int y = out.rect.y0; y < out.rect.y1; ++y)
    for (int x = out.rect.x0; x < out.rect.x1; ++x) {
      float* acc = out.rgba_at(x, y);
      float dmin = PartialImage::kNoDepth;
      for (const PartialImage* p : parts) {
        if (!p->rect.contains(x, y)) continue;
        over(acc, p->rgba_at(x, y));
        dmin = std::min(dmin, p->depth_at(x, y));
      }
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
// Anti-aliased segment coverage into a w×h float buffer (max of coverages).
void draw_segment(std::vector<float>& buf, int w, int h, double ax, double ay, double bx, double by, double width) {
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
      const double cov = std::clamp(half + 0.5 - std::sqrt(ex * ex + ey * ey), 0.0, 1.0);
      float& b = buf[std::size_t(steep ? m : n) * w + (steep ? n : m)];
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
}  // namespace

Image finish_image(const PartialImage& comp, const camera::Camera& cam, const GridGeometry& g, Rgb bg,
                   const OutlineStyle& outline) {
  const int w = cam.width(), h = cam.height();
  if (comp.width != w || comp.height != h)
    throw Error("finish_image: partial image is " + std::to_string(comp.width) + "x" + std::to_string(comp.height) +
                " but the camera's image is " + std::to_string(w) + "x" + std::to_string(h));
  std::vector<float> front, back;
  if (outline.enabled) {
    front.assign(std::size_t(w) * h, 0.0f);
    back.assign(std::size_t(w) * h, 0.0f);
    const Vec3 lo = g.domain_lo(), hi = g.domain_hi(), c = cam.position();
    // Face (axis a, side s) is turned towards the camera when the camera is beyond its plane.
    auto facing = [&](int a, int s) { return s ? c[a] > hi[a] : c[a] < lo[a]; };
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, d = (a + 2) % 3;
      for (int sb = 0; sb < 2; ++sb)
        for (int sd = 0; sd < 2; ++sd) {
          Vec3 p = lo, q = lo;
          p[b] = q[b] = sb ? hi[b] : lo[b];
          p[d] = q[d] = sd ? hi[d] : lo[d];
          q[a] = hi[a];
          double ax, ay, bx, by;
          if (!project_segment(cam, p, q, ax, ay, bx, by)) continue;
          const bool is_front = facing(b, sb) || facing(d, sd);
          draw_segment(is_front ? front : back, w, h, ax, ay, bx, by, outline.width);
        }
    }
  }
  Image img(w, h, 4);
  const float lc[3] = {outline.colour.r, outline.colour.g, outline.colour.b};
  const float bgc[3] = {bg.r, bg.g, bg.b};
#pragma omp parallel for schedule(static)
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      float c[3] = {bgc[0], bgc[1], bgc[2]};
      if (outline.enabled && back[i] > 0)
        for (int k = 0; k < 3; ++k) c[k] = back[i] * lc[k] + (1 - back[i]) * c[k];
      if (comp.rect.contains(x, y)) {
        const float* v = comp.rgba_at(x, y);
        for (int k = 0; k < 3; ++k) c[k] = v[k] + (1 - v[3]) * c[k];
      }
      if (outline.enabled && front[i] > 0)
        for (int k = 0; k < 3; ++k) c[k] = front[i] * lc[k] + (1 - front[i]) * c[k];
      std::uint8_t* o = img.at(x, y);
      for (int k = 0; k < 3; ++k) o[k] = std::uint8_t(std::lround(std::clamp(c[k], 0.0f, 1.0f) * 255.0f));
      o[3] = 255;
    }
  return img;
}

}  // namespace panoptes::render
