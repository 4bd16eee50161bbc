#pragma once
// Image-space adaptive sampling (Levoy 1990, "Volume rendering by adaptive refinement"): per tile,
// rays are marched on a coarse lattice; a lattice cell whose corners agree (same hit/miss status of
// the brick, every task's premultiplied RGBA within a tolerance) has its interior pixels filled by
// bilinear interpolation, otherwise it is split at its midpoints (stride 4 → 2 → 1) and the new
// lattice points are marched. The images of the in-situ paper settings carry 1.2–4 pixels per voxel,
// so most of a smooth image is interpolated instead of marched. Two tests end a split early: a cell
// whose first split's points are bilinear (linear()), and a 4x4 cell whose 3x3 points predict its
// sub-cell centres by their biquadratic (quadratic(): a smooth but curved image, Round 23).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <array>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "render/partial_image.hpp"

namespace panoptes::render {

/// A convex polygon of the image outside which no ray meets the brick: the convex hull of the brick's
/// 8 projected corners (perspective cameras with the brick wholly in front). Pixel (x, y)'s centre is
/// (x + 0.5, y + 0.5), as in Camera::ray.
class Silhouette {
 public:
  /// The hull of `n` <= 8 points; empty() when fewer than 3 of them are in convex position.
  Silhouette(const double* px, const double* py, int n) {
    n = std::clamp(n, 0, 8);
    std::array<std::pair<double, double>, 8> p{};
    for (int i = 0; i < n; ++i) p[std::size_t(i)] = {px[i], py[i]};
    std::sort(p.begin(), p.begin() + n);
    auto cross = [](const std::pair<double, double>& o, const std::pair<double, double>& a,
                    const std::pair<double, double>& b) {
      return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
    };
    std::array<std::pair<double, double>, 16> h{};
    int k = 0;
    for (int i = 0; i < n; ++i) {  // Andrew's monotone chain: lower hull, then upper
      while (k >= 2 && cross(h[std::size_t(k - 2)], h[std::size_t(k - 1)], p[std::size_t(i)]) <= 0) --k;
      h[std::size_t(k++)] = p[std::size_t(i)];
    }
    for (int i = n - 2, lower = k + 1; i >= 0; --i) {
      while (k >= lower && cross(h[std::size_t(k - 2)], h[std::size_t(k - 1)], p[std::size_t(i)]) <= 0) --k;
      h[std::size_t(k++)] = p[std::size_t(i)];
    }
    n_ = std::max(0, k - 1);  // the last point repeats the first
    for (int i = 0; i < n_; ++i) x_[i] = h[std::size_t(i)].first, y_[i] = h[std::size_t(i)].second;
    if (n_ < 3) n_ = 0;
  }
  bool empty() const { return n_ == 0; }
  /// True when every pixel centre of [x0, x1] × [y0, y1] lies more than a pixel outside the polygon
  /// (a margin far above any rounding of the projection), so none of their rays meets the brick.
  bool excludes(int x0, int y0, int x1, int y1) const {
    if (n_ == 0) return false;
    const double ax = x0 - 0.5, bx = x1 + 1.5, ay = y0 - 0.5, by = y1 + 1.5;  // centres ± 1 pixel
    const double cx[4] = {ax, bx, ax, bx}, cy[4] = {ay, ay, by, by};
    for (int i = 0; i < n_; ++i) {  // separating axes: the polygon's edges (counter-clockwise) ...
      const int j = i + 1 == n_ ? 0 : i + 1;
      const double ex = x_[j] - x_[i], ey = y_[j] - y_[i];
      bool out = true;
      for (int c = 0; c < 4 && out; ++c) out = ex * (cy[c] - y_[i]) - ey * (cx[c] - x_[i]) < 0;
      if (out) return true;
    }
    double lx = x_[0], hx = x_[0], ly = y_[0], hy = y_[0];  // ... and the image axes
    for (int i = 1; i < n_; ++i) lx = std::min(lx, x_[i]), hx = std::max(hx, x_[i]), ly = std::min(ly, y_[i]), hy = std::max(hy, y_[i]);
    return bx < lx || ax > hx || by < ly || ay > hy;
  }

 private:
  int n_ = 0;
  double x_[8] = {}, y_[8] = {};
};

namespace adaptive_detail {
// The bilinear blend of four corner colours, for AdaptiveTile's fill() and fill_one(): both must give
// the same bits (a K-task march's image is its one-task image). Left to itself the compiler fuses
// some products into the sums and not others, and may do so differently in the two functions (it
// did, by an ulp, in a variant of fill_one()), so where the target has a fused multiply-add the
// chain of fusions is written out; without one nothing can be fused. Internal linkage: the renderer and a
// test built with other instruction sets each keep their own.
[[maybe_unused]] static inline void bilerp(float w00, float w10, float w01, float w11, const float* a, const float* b,
                                           const float* c, const float* e, float* t) {
#ifdef FP_FAST_FMAF
  for (int k = 0; k < 4; ++k) t[k] = std::fma(w11, e[k], std::fma(w01, c[k], std::fma(w10, b[k], w00 * a[k])));
#else
  for (int k = 0; k < 4; ++k) t[k] = w00 * a[k] + w10 * b[k] + w01 * c[k] + w11 * e[k];
#endif
}
}  // namespace adaptive_detail

/// Refines one tile of a brick's partial images. All K tasks of a march (K ≤ 64) share the coarse
/// lattice, marched once for all of them; every refinement decision is then taken per task (a cell
/// is split for the tasks whose corners disagree and filled for the others), and the points of a
/// split are marched for those tasks only, so a volume task's image is exactly its one-task adaptive
/// image and a K-task march marches no ray for a task that does not need it (see `follow` in run()). `march(x, y, mask)` traces
/// pixel (x, y) exactly for the tasks in `mask` (bit i = out[i]) and writes their RGBA (transparent on
/// a miss) and every image's depth (+∞ on a miss); `locate(x, y)` returns only the pixel's exact entry
/// depth (+∞ on a miss) — the slab test, far cheaper than a march — so an interpolated pixel's depth
/// is never interpolated. Tiles are independent: the lattice includes their first and last rows and
/// columns. Lattice lines lie on multiples of `stride` in image coordinates, so bricks of one
/// decomposition sample the same pixels wherever their tiles overlap.
/// `march` returns the pixel's entry face: a non-zero id of the plane through which its ray enters
/// the brick, or 0 (a miss, or an entry that is no plane, e.g. a camera inside, or a panorama);
/// `locate(x, y, face)` with face == 0 is the full slab test, with face != 0 the four corners of the
/// pixel's cell all entered through that plane, and since the pixels whose rays enter a convex brick
/// through one face form a convex region of a perspective image, the pixel does too: `locate` then
/// only intersects that plane (the same expression as the slab test, so the same bits).
class AdaptiveTile {
 public:
  /// `stride` is the coarse lattice spacing (2 or 4; larger values work, refining by halves);
  /// `tolerance` the largest range of any premultiplied channel over a cell's corners that is still
  /// interpolated (the final image's units: 1/255 ≈ 0.0039).
  /// `linear` (0: off): a cell split at its midpoints whose new lattice points all lie within `linear`
  /// of the bilinear interpolation of its corners is filled from them without splitting further
  /// (see linear(); not in cells split with `follow` tasks, whose images then stay as without it).
  AdaptiveTile(int stride, float tolerance, float linear = 0)
      : stride_(stride), tolerance_(tolerance), linear_(linear) {}

  /// Counters of the pixels handled so far: marched (for at least one task), and interpolated for
  /// every task (marched for none).
  std::uint64_t marched() const { return marched_; }
  std::uint64_t interpolated() const { return interpolated_; }

  /// `silhouette` (may be null): cells of misses that it excludes are filled as misses without
  /// locating their pixels.
  /// `follow`: the tasks refined wherever any task is (isosurfaces and slices: their thin edges may
  /// fall between four agreeing corners, and the finer lattice of the volume tasks catches many of
  /// them, as before per-task decisions); the others decide alone.
  /// `column_stride` (0: the stride) spaces the coarse lattice's columns differently from its rows
  /// (equirectangular frames widen them toward the poles, equirect_sampling.hpp); cells are split at
  /// their midpoints on both axes as square ones are.
  /// `keyed`: images whose depth is a Blend::max order key (partial_image.hpp), not the entry depth:
  /// `march` writes it only for the tasks it marches, and an interpolated pixel takes its cell's
  /// smallest corner key (the largest maximum near it), so the bricks' join still compares maxima.
  template <class March, class Locate>
  void run(const PixelRect& tile, std::span<PartialImage> out, March&& march, Locate&& locate,
           std::uint64_t follow = 0, const Silhouette* silhouette = nullptr, int column_stride = 0,
           std::uint64_t keyed = 0) {
    if (out.size() > 64) throw std::invalid_argument("AdaptiveTile: more than 64 images in one march");
    tile_ = tile;
    keyed_ = keyed;
    follow_ = follow;
    silhouette_ = silhouette;
    out_ = out;
    const std::uint64_t all = out.size() == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << out.size()) - 1;
    const std::size_t n = std::size_t(tile.width()) * std::size_t(tile.height());
    const std::uint64_t marched_before = marched_;
    marched_for_.assign(n, 0);
    face_.resize(n);  // read only at pixels marched for some task
    // The coarse lattice: the tile's borders and the multiples of the stride between them.
    xs_.clear();
    ys_.clear();
    lattice(tile.x0, tile.x1, column_stride > 0 ? column_stride : stride_, xs_);
    lattice(tile.y0, tile.y1, stride_, ys_);
    for (int y : ys_)
      for (int x : xs_) mark_marched(x, y, all, march);
    for (std::size_t j = 0; j + 1 < ys_.size(); ++j)
      for (std::size_t i = 0; i + 1 < xs_.size(); ++i)
        refine(xs_[i], ys_[j], xs_[i + 1], ys_[j + 1], all, march, locate);
    // Every pixel of the tile is marched (for some task) or filled (for all): the lattice and its
    // cells cover the tile, and a cell is filled, split or marched whole.
    interpolated_ += n - (marched_ - marched_before);
  }

 private:
  static void lattice(int a0, int a1, int stride, std::vector<int>& v) {
    v.push_back(a0);
    for (int a = (a0 / stride + 1) * stride; a < a1 - 1; a += stride) v.push_back(a);
    v.push_back(a1 - 1);  // == a0 for a tile one pixel wide: cells of width 0 then cover its column
  }
  std::size_t at(int x, int y) const {
    return std::size_t(y - tile_.y0) * std::size_t(tile_.width()) + std::size_t(x - tile_.x0);
  }
  float depth(const PartialImage& o, int x, int y) const {
    return o.depth[std::size_t(y - o.rect.y0) * std::size_t(o.rect.width()) + std::size_t(x - o.rect.x0)];
  }
  // The entry face shared by the four corners of a cell whose corners hit, 0 when they differ: every
  // pixel of the cell then enters through it too (see the class comment), so locate() may use it.
  std::uint8_t cell_face(int x0, int y0, int x1, int y1) const {
    const std::uint8_t face = face_[at(x0, y0)];
    return face_[at(x1, y0)] == face && face_[at(x0, y1)] == face && face_[at(x1, y1)] == face ? face : 0;
  }
  // Marches pixel (x, y) for the tasks of `mask` it was not marched for yet.
  template <class March>
  void mark_marched(int x, int y, std::uint64_t mask, March& march) {
    std::uint64_t& s = marched_for_[at(x, y)];
    const std::uint64_t m = mask & ~s;
    if (!m) return;
    face_[at(x, y)] = march(x, y, m);
    if (!s) ++marched_;
    s |= m;
  }

  // The tasks of `mask` whose four corners of cell [x0, x1] × [y0, y1] do not agree closely enough
  // to interpolate between them (all of them where the corners' hit/miss status differs).
  std::uint64_t rough(int x0, int y0, int x1, int y1, std::uint64_t mask) const {
    const PartialImage& o0 = out_[0];
    const bool hit = depth(o0, x0, y0) != PartialImage::kNoDepth;
    if ((depth(o0, x1, y0) != PartialImage::kNoDepth) != hit || (depth(o0, x0, y1) != PartialImage::kNoDepth) != hit ||
        (depth(o0, x1, y1) != PartialImage::kNoDepth) != hit)
      return mask;
    if (!hit) return 0;
    std::uint64_t r = 0;
    for (std::uint64_t m = mask; m; m &= m - 1) {
      const PartialImage& o = out_[std::size_t(std::countr_zero(m))];
      if (keyed_ & m & -m) {
        // A max-blend image whose corners disagree on having samples in the brick: between them
        // the brick's part of the ray ends, and an interpolated translucent pixel would win the
        // bricks' join whole (a max keeps one partial), letting the background through.
        const bool sampled = depth(o, x0, y0) != PartialImage::kNoDepth;
        if ((depth(o, x1, y0) != PartialImage::kNoDepth) != sampled ||
            (depth(o, x0, y1) != PartialImage::kNoDepth) != sampled ||
            (depth(o, x1, y1) != PartialImage::kNoDepth) != sampled) {
          r |= m & -m;
          continue;
        }
      }
      if (o.slivers && !slivers_agree(o, x0, y0, x1, y1)) {
        r |= m & -m;
        continue;
      }
      const float *a = o.rgba_at(x0, y0), *b = o.rgba_at(x1, y0), *c = o.rgba_at(x0, y1), *d = o.rgba_at(x1, y1);
      // Plain comparisons, not std::fmin/fmax (libm calls here, NaN-aware): the march writes finite
      // colours (LUT entries times opacities), and the range of finite values is the same.
      auto lower = [](float p, float q) { return q < p ? q : p; };
      auto upper = [](float p, float q) { return p < q ? q : p; };
      for (int k = 0; k < 4; ++k) {
        const float lo = lower(lower(a[k], b[k]), lower(c[k], d[k]));
        const float hi = upper(upper(a[k], b[k]), upper(c[k], d[k]));
        if (hi - lo > tolerance_) {
          r |= m & -m;
          break;
        }
      }
    }
    return r ? r | (mask & follow_) : 0;
  }

  // An anti-aliased isosurface's sliver state (PartialImage::slivers) at the cell's corners: the same
  // end state, and colours if a sliver is open at the brick's front within the tolerance, so that
  // both of the brick's colours may be interpolated (the bricks in front pick one per pixel).
  bool slivers_agree(const PartialImage& o, int x0, int y0, int x1, int y1) const {
    const std::size_t i[4] = {o.index(x0, y0), o.index(x1, y0), o.index(x0, y1), o.index(x1, y1)};
    const SliverEnd e = o.sliver_end[i[0]];
    if (o.sliver_end[i[1]] != e || o.sliver_end[i[2]] != e || o.sliver_end[i[3]] != e) return false;
    for (int k = 0; k < 4; ++k) {
      float lo = o.rgba_open[4 * i[0] + k], hi = lo;
      for (int c = 1; c < 4; ++c) {
        const float v = o.rgba_open[4 * i[c] + std::size_t(k)];
        lo = v < lo ? v : lo, hi = hi < v ? v : hi;
      }
      if (hi - lo > tolerance_) return false;
    }
    return true;
  }

  template <class March, class Locate>
  void refine(int x0, int y0, int x1, int y1, std::uint64_t mask, March& march, Locate& locate) {
    if (x1 - x0 <= 1 && y1 - y0 <= 1) return;  // no pixels inside
    const std::uint64_t r = rough(x0, y0, x1, y1, mask);
    if (mask & ~r) fill(x0, y0, x1, y1, mask & ~r, march, locate);
    if (!r) return;
    if (x1 - x0 <= 2 && y1 - y0 <= 2) {
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) mark_marched(x, y, r, march);
      return;
    }
    // Split at the midpoints (an axis already down to one pixel is not split).
    int xv[3] = {x0, (x0 + x1) / 2, x1}, yv[3] = {y0, (y0 + y1) / 2, y1};
    const int nx = x1 - x0 >= 2 ? 3 : 2, ny = y1 - y0 >= 2 ? 3 : 2;
    if (nx == 2) xv[1] = x1;
    if (ny == 2) yv[1] = y1;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) mark_marched(xv[i], yv[j], r, march);
    // Not where `follow` tasks are split with this cell: they are refined wherever any task is, and
    // would lose that refinement in the sub-cells of the tasks filled here.
    const std::uint64_t lin = linear_ > 0 && !(r & follow_) ? linear(x0, y0, x1, y1, xv, nx, yv, ny, r) : 0;
    const std::uint64_t quad = linear_ > 0 && !(r & follow_) && (r & ~lin) && x1 - x0 == 4 && y1 - y0 == 4
                                   ? quadratic(x0, y0, r & ~lin, march, locate)
                                   : 0;
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        if (lin) fill(xv[i], yv[j], xv[i + 1], yv[j + 1], lin, march, locate);
        if (r & ~lin & ~quad) refine(xv[i], yv[j], xv[i + 1], yv[j + 1], r & ~lin & ~quad, march, locate);
      }
  }

  // Lagrange weights of the nodes 0, 2, 4 at offset t = 0 … 4 of a 4-pixel cell.
  static constexpr float kQuad[5][3] = {
      {1, 0, 0}, {0.375f, 0.75f, -0.125f}, {0, 1, 0}, {-0.125f, 0.75f, 0.375f}, {0, 0, 1}};

  // The biquadratic through a 4x4 cell's 3x3 lattice (corners, edge midpoints, centre) at offset (i, j).
  static void biquadratic(const PartialImage& o, int x0, int y0, int i, int j, float* t) {
    for (int k = 0; k < 4; ++k) t[k] = 0;
    for (int b = 0; b < 3; ++b)
      for (int a = 0; a < 3; ++a) {
        const float w = kQuad[i][a] * kQuad[j][b];
        if (w == 0) continue;
        const float* q = o.rgba_at(x0 + 2 * a, y0 + 2 * b);
        for (int k = 0; k < 4; ++k) t[k] += w * q[k];
      }
  }

  // A 4x4 cell (the stride-4 lattice's) split at its midpoints whose new points are not bilinear
  // for the tasks of `mask`: its level-two cells would march 12 more of its pixels for them. Where
  // the image is smooth but curved, the biquadratic through the 3x3 points already marched predicts
  // them; its four sub-cell centres are marched to check it, and the tasks (plain images) whose
  // centres all lie within linear_ of it are filled from it (returned); the rest split further.
  template <class March, class Locate>
  std::uint64_t quadratic(int x0, int y0, std::uint64_t mask, March& march, Locate& locate) {
    const PartialImage& o0 = out_[0];
    for (int b = 0; b < 3; ++b)
      for (int a = 0; a < 3; ++a)
        if (depth(o0, x0 + 2 * a, y0 + 2 * b) == PartialImage::kNoDepth) return 0;
    std::uint64_t plain = 0;
    for (std::uint64_t m = mask & ~keyed_; m; m &= m - 1)
      if (!out_[std::size_t(std::countr_zero(m))].slivers) plain |= m & -m;
    if (!plain) return 0;
    const int cx[4] = {1, 3, 1, 3}, cy[4] = {1, 1, 3, 3};
    for (int c = 0; c < 4; ++c) {
      mark_marched(x0 + cx[c], y0 + cy[c], plain, march);
      if (depth(o0, x0 + cx[c], y0 + cy[c]) == PartialImage::kNoDepth) return 0;
    }
    std::uint64_t ok = 0;
    for (std::uint64_t m = plain; m; m &= m - 1) {
      const PartialImage& o = out_[std::size_t(std::countr_zero(m))];
      bool good = true;
      for (int c = 0; c < 4 && good; ++c) {
        float t[4];
        biquadratic(o, x0, y0, cx[c], cy[c], t);
        const float* q = o.rgba_at(x0 + cx[c], y0 + cy[c]);
        for (int k = 0; k < 4; ++k)
          if (q[k] - t[k] > linear_ || q[k] - t[k] < -linear_) good = false;
      }
      if (good) ok |= m & -m;
    }
    if (ok) fill_quadratic(x0, y0, ok, march, locate);
    return ok;
  }

  // The cell's pixels not marched for the tasks of `mask` from the biquadratic (quadratic()); a pixel
  // whose exact hit/miss status is a miss is marched instead, as in fill().
  template <class March, class Locate>
  void fill_quadratic(int x0, int y0, std::uint64_t mask, March& march, Locate& locate) {
    const std::uint8_t face = cell_face(x0, y0, x0 + 4, y0 + 4);  // its nine points hit (quadratic())
    for (int j = 0; j <= 4; ++j)
      for (int i = 0; i <= 4; ++i) {
        const int x = x0 + i, y = y0 + j;
        const std::size_t p = at(x, y);
        const std::uint64_t pending = mask & ~marched_for_[p];
        if (!pending) continue;
        const float d = locate(x, y, face);
        if (d == PartialImage::kNoDepth) {
          mark_marched(x, y, pending, march);
          continue;
        }
        for (std::uint64_t m = pending; m; m &= m - 1) {
          PartialImage& o = out_[std::size_t(std::countr_zero(m))];
          float t[4];
          biquadratic(o, x0, y0, i, j, t);
          std::copy_n(t, 4, o.rgba_at(x, y));
        }
        for (std::size_t k = 0; k < out_.size(); ++k)
          if (!(keyed_ >> k & 1)) out_[k].depth[out_[k].index(x, y)] = d;
      }
  }

  // The tasks of `mask` (plain ones: no keyed or sliver images) for which the cell's new
  // lattice points (xv × yv, just marched) are within linear_ of the bilinear interpolation of its
  // four corners: the image is bilinear there to that tolerance, so the sub-cells are filled from
  // their own corners without splitting further (Round 13). The range test alone splits every cell
  // across which the image changes by more than the tolerance, even where it changes linearly — in
  // a dense field most cells — and their sub-cells again, down to single pixels; this test ends the
  // split one level up where the first level's midpoints show that it may. Every new point of the
  // split is still marched, and a cell whose corners or new points disagree on hit or miss goes on
  // splitting as before.
  std::uint64_t linear(int x0, int y0, int x1, int y1, const int* xv, int nx, const int* yv, int ny,
                       std::uint64_t mask) const {
    const PartialImage& o0 = out_[0];
    const bool hit = depth(o0, x0, y0) != PartialImage::kNoDepth;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if ((depth(o0, xv[i], yv[j]) != PartialImage::kNoDepth) != hit) return 0;
    if (!hit) return 0;
    const float sx = x1 > x0 ? 1.0f / float(x1 - x0) : 0.0f, sy = y1 > y0 ? 1.0f / float(y1 - y0) : 0.0f;
    std::uint64_t lin = 0;
    for (std::uint64_t m = mask & ~keyed_; m; m &= m - 1) {
      const PartialImage& o = out_[std::size_t(std::countr_zero(m))];
      if (o.slivers) continue;
      const float *a = o.rgba_at(x0, y0), *b = o.rgba_at(x1, y0), *c = o.rgba_at(x0, y1), *d = o.rgba_at(x1, y1);
      bool ok = true;
      for (int j = 0; j < ny && ok; ++j)
        for (int i = 0; i < nx && ok; ++i) {
          const float u = float(xv[i] - x0) * sx, v = float(yv[j] - y0) * sy;
          const float w00 = (1 - u) * (1 - v), w10 = u * (1 - v), w01 = (1 - u) * v, w11 = u * v;
          const float* q = o.rgba_at(xv[i], yv[j]);
          for (int k = 0; k < 4; ++k) {
            const float e = q[k] - (w00 * a[k] + w10 * b[k] + w01 * c[k] + w11 * d[k]);
            if (e > linear_ || e < -linear_) ok = false;
          }
        }
      if (ok) lin |= m & -m;
    }
    return lin;
  }

  // fill() for the common march of one plain image (one task, no slivers, no order key): the same
  // decisions and values without the per-task masks and tables, whose spills cost more than the
  // blend itself (a filled pixel cost ~70 cycles in fill() on the ParaView anchor).
  template <class March, class Locate>
  void fill_one(int x0, int y0, int x1, int y1, bool hit, std::uint8_t face, bool outside, March& march,
                Locate& locate) {
    PartialImage& o = out_[0];
    // The corners are marched pixels, never written below: copies keep them in registers.
    float a[4], b[4], c[4], e[4];
    std::copy_n(o.rgba_at(x0, y0), 4, a), std::copy_n(o.rgba_at(x1, y0), 4, b);
    std::copy_n(o.rgba_at(x0, y1), 4, c), std::copy_n(o.rgba_at(x1, y1), 4, e);
    const float sx = x1 > x0 ? 1.0f / float(x1 - x0) : 0.0f, sy = y1 > y0 ? 1.0f / float(y1 - y0) : 0.0f;
    for (int y = y0; y <= y1; ++y) {
      const float v = float(y - y0) * sy;
      float* row = o.rgba_at(x0, y);
      float* drow = &o.depth[o.index(x0, y)];
      const std::size_t p0 = at(x0, y);
      for (int x = x0; x <= x1; ++x) {
        const std::size_t dx = std::size_t(x - x0);
        if (marched_for_[p0 + dx]) continue;
        const float d = outside ? PartialImage::kNoDepth : locate(x, y, face);
        if ((d != PartialImage::kNoDepth) != hit) {
          mark_marched(x, y, 1, march);
          continue;
        }
        if (hit) {
          const float u = float(x - x0) * sx;
          const float w00 = (1 - u) * (1 - v), w10 = u * (1 - v), w01 = (1 - u) * v, w11 = u * v;
          float t[4];
          adaptive_detail::bilerp(w00, w10, w01, w11, a, b, c, e, t);
          std::copy_n(t, 4, row + 4 * dx);
        } else {
          std::fill_n(row + 4 * dx, 4, 0.0f);
        }
        drow[dx] = d;
      }
    }
  }

  // Bilinear interpolation, for the tasks of `mask`, of the cell's pixels not marched for them. A
  // pixel whose exact hit/miss status differs from its corners' (the brick's silhouette crossing a
  // cell, e.g. a thin brick seen edge-on between four misses) is marched instead.
  template <class March, class Locate>
  void fill(int x0, int y0, int x1, int y1, std::uint64_t mask, March& march, Locate& locate) {
    const bool hit = depth(out_[0], x0, y0) != PartialImage::kNoDepth;
    // All four corners entered through one plane: the interior did too (see the class comment).
    const std::uint8_t face = hit ? cell_face(x0, y0, x1, y1) : 0;
    // Four misses well outside the brick's silhouette: no pixel between them can hit.
    const bool outside = !hit && silhouette_ && silhouette_->excludes(x0, y0, x1, y1);
    if (out_.size() == 1 && !keyed_ && !out_[0].slivers) return fill_one(x0, y0, x1, y1, hit, face, outside, march, locate);
    const float sx = x1 > x0 ? 1.0f / float(x1 - x0) : 0.0f, sy = y1 > y0 ? 1.0f / float(y1 - y0) : 0.0f;
    // The cell's corners in every image of `mask`, looked up once per cell instead of once per pixel.
    std::array<std::array<const float*, 4>, 64> corners;
    for (std::uint64_t m = mask; m; m &= m - 1) {
      const std::size_t i = std::size_t(std::countr_zero(m));
      const PartialImage& o = out_[i];
      corners[i] = {o.rgba_at(x0, y0), o.rgba_at(x1, y0), o.rgba_at(x0, y1), o.rgba_at(x1, y1)};
    }
    // Per row, each image's pixel (x0, y) and depth there, so a pixel costs an offset, not an index.
    std::array<float*, 64> row, drow;
    for (int y = y0; y <= y1; ++y) {
      const float v = float(y - y0) * sy;
      for (std::uint64_t m = mask; m; m &= m - 1) {
        const std::size_t i = std::size_t(std::countr_zero(m));
        row[i] = out_[i].rgba_at(x0, y);
      }
      for (std::size_t i = 0; i < out_.size(); ++i) drow[i] = &out_[i].depth[out_[i].index(x0, y)];
      for (int x = x0; x <= x1; ++x) {
        const std::size_t p = at(x, y);
        const std::uint64_t pending = mask & ~marched_for_[p];
        if (!pending) continue;
        const float d = outside ? PartialImage::kNoDepth : locate(x, y, face);
        if ((d != PartialImage::kNoDepth) != hit) {
          mark_marched(x, y, pending, march);
          continue;
        }
        const std::size_t dx = std::size_t(x - x0);
        if (hit) {
          const float u = float(x - x0) * sx;
          const float w00 = (1 - u) * (1 - v), w10 = u * (1 - v), w01 = (1 - u) * v, w11 = u * v;
          for (std::uint64_t m = pending; m; m &= m - 1) {
            const std::size_t i = std::size_t(std::countr_zero(m));
            const auto& [a, b, c, e] = corners[i];
            // Into a local first: the corners may be this image's pixels, so the compiler could not
            // take the four channels at once.
            float t[4];
            adaptive_detail::bilerp(w00, w10, w01, w11, a, b, c, e, t);
            std::copy_n(t, 4, row[i] + 4 * dx);
            if (PartialImage& o = out_[i]; o.slivers) {  // the corners' end state agrees (rough())
              const float *oa = &o.rgba_open[4 * o.index(x0, y0)], *ob = &o.rgba_open[4 * o.index(x1, y0)],
                          *oc = &o.rgba_open[4 * o.index(x0, y1)], *od = &o.rgba_open[4 * o.index(x1, y1)];
              float* qo = &o.rgba_open[4 * o.index(x, y)];
              for (int k = 0; k < 4; ++k) qo[k] = w00 * oa[k] + w10 * ob[k] + w01 * oc[k] + w11 * od[k];
              o.sliver_end[o.index(x, y)] = o.sliver_end[o.index(x0, y0)];
            }
          }
        } else {
          for (std::uint64_t m = pending; m; m &= m - 1) {
            const std::size_t i = std::size_t(std::countr_zero(m));
            PartialImage& o = out_[i];
            std::fill_n(row[i] + 4 * dx, 4, 0.0f);
            if (o.slivers) {
              std::fill_n(&o.rgba_open[4 * o.index(x, y)], 4, 0.0f);
              o.sliver_end[o.index(x, y)] = SliverEnd::pass;
            }
          }
        }
        for (std::size_t i = 0; i < out_.size(); ++i) {  // the same exact depth for every image but keyed ones
          float& dst = drow[i][dx];
          if (!(keyed_ >> i & 1)) {
            dst = d;
          } else if (pending >> i & 1) {
            const PartialImage& o = out_[i];
            dst = !hit ? PartialImage::kNoDepth
                       : std::min(std::min(depth(o, x0, y0), depth(o, x1, y0)), std::min(depth(o, x0, y1), depth(o, x1, y1)));
          }
        }
      }
    }
  }

  int stride_;
  float tolerance_;
  float linear_ = 0;
  std::uint64_t follow_ = 0, keyed_ = 0;
  PixelRect tile_;
  std::span<PartialImage> out_;
  const Silhouette* silhouette_ = nullptr;
  std::vector<std::uint64_t> marched_for_;  // per pixel of the tile: the tasks it was marched for
  std::vector<std::uint8_t> face_;          // per pixel: march()'s entry face
  std::vector<int> xs_, ys_;
  std::uint64_t marched_ = 0, interpolated_ = 0;
};

}  // namespace panoptes::render
