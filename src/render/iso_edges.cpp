#include "render/iso_edges.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "render/iso_shading.hpp"

namespace panoptes::render::march {

double pixel_pitch(const camera::Camera& cam) {
  const double x = 0.5 * cam.width(), y = 0.5 * cam.height();
  const Vec3 a = normalize(cam.ray(x, y).direction), b = normalize(cam.ray(x, y + 1).direction);
  return std::acos(std::clamp(dot(a, b), -1.0, 1.0));
}

namespace {

// Whether a near miss at index position p (value iso + sv, gradient g, |g| = gn) has the surface in
// its own grid cell or a neighbour: one Newton step towards the surface lands in a cell whose corners
// bracket the isovalue. Every macro-cell containing p then contains the isovalue (their min/max
// include a one-point margin), so every brick decomposition marches the sample: the event is seen
// alike by all of them (without this check a near miss in a cell skipped by one decomposition
// changed a pixel by 2/255).
bool near_surface(const FieldAcc& f, const MarchPlan& S, float iso, const double p[3], double sv, const double g[3],
                  double gn) {
  int c[3];
  for (int a = 0; a < 3; ++a) {
    const double q = p[a] - sv * g[a] / (gn * gn) / S.spacing[a];  // g per world unit, p in index units
    c[a] = int(std::floor(q));
    const int own = int(std::floor(p[a]));
    if (std::abs(c[a] - own) > 1 || c[a] < f.ilo[a] || c[a] > f.ihi[a]) return false;
  }
  const float* d = f.data + (f.off0 + c[0] * f.sx + c[1] * f.sy + c[2] * f.sz);
  float lo = d[0], hi = d[0];
  for (int corner = 1; corner < 8; ++corner) {
    const float v = d[(corner & 1 ? f.sx : 0) + (corner & 2 ? f.sy : 0) + (corner & 4 ? f.sz : 0)];
    lo = std::min(lo, v), hi = std::max(hi, v);
  }
  return lo <= iso && iso <= hi;
}

}  // namespace

int march_iso_block_aa(const MarchPlan& S, const MarchTask& T, const FieldAcc& f, const RayPos& P, const double O[3],
                       const double D[3], const Vec3& dir, double t0, std::int64_t k0, int n, const float* v,
                       const float* range, unsigned cand, std::int64_t k_last, double t_exit, float tr_stop, float* a,
                       IsoSliver& sliver) {
  const double dt = S.dt, pitch = S.iso_aa_pitch;
  const double half_voxel = 0.5 * std::min({S.spacing[0], S.spacing[1], S.spacing[2]});
  const float iso = T.iso;
  // How far (in samples) a grazing ray's vertex may lie from its crossing: the chord of a sphere of
  // radius R at depth x is 2·√(2Rx), ~4 voxels for R = 16 voxels at x = 1/8 voxel.
  const double max_reach = 4.0 * S.grid.voxel() / dt;
  // s(j) = f − iso at sample k0 − 1 + j; j = n + 1 (the sample after the block) only on demand.
  float after = 0;
  bool have_after = false;
  // The previous block's pending last lane (sample k0 − 1, lane j = 0 below) when this block follows
  // it; otherwise it is looked at alone first.
  bool lane0 = false;
  float pend_sp = 0;
  if (sliver.pending) {
    if (k0 == sliver.pend_k + 1) {
      sliver.pending = false;
      lane0 = true;
      pend_sp = sliver.pend_v[0];
    } else if (resolve_pending_lane(S, T, f, P, O, D, dir, t0, k_last, t_exit, tr_stop, a, sliver) >= 0) {
      return 0;
    }
  }
  // This block's last lane waits for the next block when it is a minimum candidate only (not the
  // ray's last sample: no block follows that; nor a block of one sample).
  const bool defer = (cand >> (n - 1) & 1) && n > 1 && k0 + n - 1 != k_last && (v[n - 1] < iso) == (v[n] < iso);
  if (defer) cand &= ~(1u << (n - 1));
  auto s = [&](int j) -> float {
    if (j < 0) return pend_sp - iso;
    if (j <= n) return v[j] - iso;
    if (!have_after) {
      const float fk = float(k0 + n);  // the march's float positions (as interp_block's)
      after = interp_clamped(f, P.bx + fk * P.sx, P.by + fk * P.sy, P.bz + fk * P.sz);
      have_after = true;
    }
    return after - iso;
  };
  // Composites one event of coverage alpha with shading rgb; true when the task is done.
  auto add = [&](const float rgb[4], double alpha) {
    const float T0 = a[3], w = float(T0 * alpha);
    for (int c = 0; c < 3; ++c) a[c] += w * rgb[c];
    a[3] = alpha >= 1 ? 0.0f : float(T0 * (1 - alpha));
    return a[3] <= tr_stop;
  };
  const float hmin = float(std::min({S.spacing[0], S.spacing[1], S.spacing[2]}));
  // The hit on a bracket [ta, tb] whose field values minus the isovalue (sa, sb) differ in sign: the
  // linear estimate and one regula-falsi step.
  const auto refine_hit = [&](double ta, double tb, double sa, double sb) {
    double th = ta + (tb - ta) * (sa / (sa - sb));
    const double vh = interp_clamped(f, O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]) - iso;
    if ((vh < 0) == (sa < 0)) ta = th, sa = vh;
    else tb = th, sb = vh;
    if (sa != sb) th = ta + (tb - ta) * (sa / (sa - sb));
    return th;
  };
  // Bit j for lane j: sample k0 − 1 + j (lane 0: the previous block's pending lane).
  for (std::uint32_t lanes = cand << 1 | unsigned(lane0); lanes; lanes &= lanes - 1) {
    const int j = std::countr_zero(lanes);
    const float sp = s(j - 1), sc = s(j);
    const bool cross = (sp < 0) != (sc < 0);
    const std::int64_t k = k0 - 1 + j;
    float cell_range = 0;
    if (!cross && j == 0 && sliver.pend_ranged) {
      cell_range = sliver.pend_range;  // tested in the previous block
    } else if (!cross && j > 0 && range) {
      cell_range = range[j - 1];  // tested above
    } else if (!cross) {
      // A near miss needs the surface within half a voxel: in this grid cell, |∇f| per voxel is at
      // most √3 × the corners' range r, so |s| > r (a factor 2 of margin) cannot be one. 8 loads
      // instead of a gradient for most local minima of a wavy field.
      const float fk = float(k);
      const float x = std::clamp(P.bx + fk * P.sx, f.plo[0], f.phi[0]), y = std::clamp(P.by + fk * P.sy, f.plo[1], f.phi[1]),
                  z = std::clamp(P.bz + fk * P.sz, f.plo[2], f.phi[2]);
      const int ci = std::min(std::max(int(x), f.ilo[0]), f.ihi[0]), cj = std::min(std::max(int(y), f.ilo[1]), f.ihi[1]),
                ck = std::min(std::max(int(z), f.ilo[2]), f.ihi[2]);
      const float* d = f.data + (f.off0 + ci * f.sx + cj * f.sy + ck * f.sz);
      float lo = d[0], hi = d[0];
      for (int corner = 1; corner < 8; ++corner) {
        const float w = d[(corner & 1 ? f.sx : 0) + (corner & 2 ? f.sy : 0) + (corner & 4 ? f.sz : 0)];
        lo = std::min(lo, w), hi = std::max(hi, w);
      }
      cell_range = hi - lo;
      if (!(std::abs(sc) <= cell_range)) continue;
    }
    const float sn = s(j + 1);
    if (!cross && ((sn < 0) != (sc < 0) || std::abs(sc) > std::abs(sn))) continue;  // not a local minimum of |s|
    // The parabola through samples j − 1, j, j + 1 (u = −1, 0, 1): its vertex u_v and value s_v.
    const double b = 0.5 * (double(sn) - double(sp)), c2 = 0.5 * (double(sn) - 2.0 * double(sc) + double(sp));
    const double uv = c2 != 0 ? -b / (2 * c2) : INFINITY;
    const double sv = c2 != 0 ? double(sc) - b * b / (4 * c2) : double(sc);
    alignas(16) float rgb[4];
    float gs[8];  // the values shade_hit()'s gradient read (shade_hit_footprint()'s cheap look)
    double g[3], gn = 0;
    if (cross) {
      // The hit: linear estimate and one regula-falsi step, as without anti-aliasing.
      const double ta = t0 + double(k - 1) * dt;
      const double th = refine_hit(ta, ta + dt, sp, sc);
      const double ph[3] = {O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]};
      shade_hit(f, S.grid.dims, S.spacing, ph, dir, T.colour, rgb, g, gs);
      gn = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
      // The shading filtered over the pixel footprint (issue 41's last speckles: one shading sample
      // where the reference's sub-rays see a grazing rim, a crease or a highlight narrower than the
      // pixel), only for events that add it (an exit that closes a sliver adds nothing). Its reads
      // stay within a voxel of the hit on every axis (the ghost layers: required_points()), so every
      // brick computes the same.
      const auto filter = [&] {
        shade_hit_footprint(f, S.grid.dims, S.spacing, ph, dir, g, th * pitch, half_voxel, T.iso, T.colour, rgb, gs);
      };
      double alpha = 1;
      // A grazing ray: the parabola has a second root close by (its vertex on the other side of
      // zero than its curvature, within max_reach of the crossing), so the ray leaves the surface
      // again soon. The entry (vertex ahead) takes the coverage; the exit (vertex behind) adds
      // nothing, so the pair covers `cover`. (Letting an exit with nothing before it on the ray
      // count broke compositing: the entry may lie in the brick in front.)
      const double uc = -1 + double(sp) / (double(sp) - double(sc));  // the crossing in u
      // Only where a pixel is a sizeable part of a voxel (>= 1/4): in views magnified beyond that
      // (inside the data, near the camera) a fit across a crease of the trilinear field could
      // predict an exit that never comes, and the ray would see the dark behind (dotted lines).
      if (std::abs(uv - uc) <= max_reach && c2 * sv < 0 && gn > 0 && th * pitch >= 0.25 * hmin) {
        // The samples' curvature of s along the ray mixes the surface's bend with how the field
        // changes across the surface (its second derivative along the normal, |∇f| varying along
        // the ray); only the bend makes the ray leave the surface again. A ray crossing a sheet
        // where the field's own curvature turned the parabola back was taken for one end of a
        // sliver: as an exit it got nothing and showed what lay behind — often the black
        // background — as an entry too little coverage (issue 41's speckles). So the bend is
        // measured from the gradients at the two samples around the hit (H·u by their difference;
        // both lie within the ghost layers, so every brick computes the same): s'' of the surface
        // = u·Hu − (n·Hu)(n·u), n = ∇f / |∇f|. It must curve the way the samples do, and it alone
        // sets the vertex (on a distance field, where s'' is the bend alone, the samples' parabola
        // scattered by a factor 2 around it): s' = ∇f·u, the vertex lies −s'/s'' along the ray,
        // |s| there is s'² / (2|s''|), and the pixel's centre lies that over |∇f| inside the
        // surface's outline (coverage 0.5 + depth / footprint, box filter). Still taken for an
        // exit: a first crossing where the bend does curve back but the region behind is open
        // towards the camera (a valley where two sheets meet); telling it from a real exit needs
        // the ray's earlier crossings, which a brick does not see when they lie in the brick in
        // front: the sliver state below, carried across bricks by compositing (docs/rendering.md,
        // "Isosurface anti-aliasing").
        double gm[3], gq[3], Hu[3];
        const double tm = t0 + double(k - 1) * dt, tq = tm + dt;
        const double pm[3] = {O[0] + tm * D[0], O[1] + tm * D[1], O[2] + tm * D[2]};
        const double pq[3] = {O[0] + tq * D[0], O[1] + tq * D[1], O[2] + tq * D[2]};
        field_gradient(f, S.grid.dims, S.spacing, pm, gm);
        field_gradient(f, S.grid.dims, S.spacing, pq, gq);
        for (int c = 0; c < 3; ++c) Hu[c] = (gq[c] - gm[c]) / dt;
        const double s1 = g[0] * dir[0] + g[1] * dir[1] + g[2] * dir[2];
        const double uHu = Hu[0] * dir[0] + Hu[1] * dir[1] + Hu[2] * dir[2];
        const double nHu = (Hu[0] * g[0] + Hu[1] * g[1] + Hu[2] * g[2]) / gn;
        const double s2 = uHu - nHu * (s1 / gn);
        if (s2 * c2 > 0) {
          const double reach = -s1 / s2;  // world units from the hit to the vertex
          if (std::abs(reach) <= max_reach * dt) {
            const double cover = 0.5 + s1 * s1 / (2 * std::abs(s2)) / gn / (th * pitch);
            if (cover < 1) {
              if (reach > 0) {  // an entry: it takes the coverage, its exit comes later
                alpha = cover;
                sliver.state = SliverEnd::open;
                filter();
                if (add(rgb, alpha)) return std::max(j - 1, 0);
                continue;
              }
              // An exit adds nothing when its entry came before it on the ray. Without one the sliver
              // the local fit claims behind is open towards the camera (a valley where two sheets
              // meet, issue 41's cracks and speckles) and the crossing is the ray's hit. Whether an
              // entry came may be up to the bricks in front (state pass): the march goes on as if
              // one did and keeps the hit in `alt` (compositing picks, PartialImage::rgba_open).
              if (sliver.state == SliverEnd::open) {
                sliver.state = SliverEnd::closed;
                continue;
              }
              if (sliver.state == SliverEnd::pass) {
                const float T0 = a[3];
                filter();
                for (int c = 0; c < 3; ++c) sliver.alt[c] = a[c] + T0 * rgb[c];
                sliver.alt[3] = 0;
                sliver.has_alt = true;
                sliver.state = SliverEnd::closed;
                continue;
              }
            }
          }
        }
      }
      sliver.state = SliverEnd::closed;  // an opaque hit
      if (alpha <= 0) continue;
      filter();
      if (add(rgb, alpha)) return std::max(j - 1, 0);
      continue;
    }
    // A local minimum of |s|: the ray passes near the surface, or pierces a sliver of it between
    // two samples (the saw teeth of grazing views: whether a sample fell inside the sliver decided
    // hit or miss). The field at the parabola's vertex tells which.
    // Up to three parabolic steps on the bracket (u = −1, 0, 1 around sample k) towards the minimum
    // of |s|; a value of the other sign is a sliver, whose entry lies between the last point
    // before it (same sign) and it.
    // Between samples dt apart, |s| falls at most dt/2 · √3·r / h below the nearest of them (r: the
    // cell's range, as the near-miss test above): where even that bound stays away from zero and
    // beyond the near-miss test's reach below, the search can find neither a sliver nor a near miss.
    if (!cross && cell_range > 0) {
      const double floor_s = std::abs(double(sc)) - 0.87 * double(cell_range) * dt / double(hmin);
      if (floor_s > 0 && floor_s * hmin > 0.87 * cell_range * (t0 + (double(k) + 1) * dt) * pitch) continue;
    }
    double ua = -1, ub = 0, uz = 1, fa = sp, fb = sc, fz = sn;
    bool pierced = false;
    double u_in = 0, s_in = 0, u_out = 0, s_out = 0;
    for (int it = 0; it < 3 && !pierced; ++it) {
      const double p = (ub - ua) * (ub - ua) * (fb - fz) - (ub - uz) * (ub - uz) * (fb - fa);
      const double q = (ub - ua) * (fb - fz) - (ub - uz) * (fb - fa);
      double u = q != 0 ? ub - 0.5 * p / q : ub;
      if (!(u > ua && u < uz) || std::abs(u - ub) < 1e-3) u = ub - ua > uz - ub ? 0.5 * (ua + ub) : 0.5 * (ub + uz);
      const double tu = t0 + (double(k) + u) * dt;
      const double su = double(interp_clamped(f, O[0] + tu * D[0], O[1] + tu * D[1], O[2] + tu * D[2]) - iso);
      if ((su < 0) != (sc < 0)) {
        pierced = true;
        u_out = u, s_out = su;
        if (u > ub) u_in = ub, s_in = fb;
        else u_in = ua, s_in = fa;
      } else if (std::abs(su) < std::abs(fb)) {
        if (u > ub) ua = ub, fa = fb;
        else uz = ub, fz = fb;
        ub = u, fb = su;
      } else if (u > ub) {
        uz = u, fz = su;
      } else {
        ua = u, fa = su;
      }
    }
    if (pierced) {
      // A sliver: the entry by regula falsi between u_in and u_out.
      const double th = refine_hit(t0 + (double(k) + u_in) * dt, t0 + (double(k) + u_out) * dt, s_in, s_out);
      const double ph[3] = {O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]};
      shade_hit(f, S.grid.dims, S.spacing, ph, dir, T.colour, rgb, g, gs);
      gn = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
      // Its depth is at least |s| at the point found / |∇f|: coverage of the pair in one event.
      const double cover = gn > 0 && th > 0 ? 0.5 + std::abs(s_out) / gn / (th * pitch) : 1.0;
      shade_hit_footprint(f, S.grid.dims, S.spacing, ph, dir, g, th * pitch, half_voxel, T.iso, T.colour, rgb, gs);
      if (add(rgb, std::min(1.0, cover))) return std::max(j - 1, 0);
      continue;
    }
    const double tv = t0 + (double(k) + ub) * dt, s_v = fb;
    if (!(tv > 0)) continue;
    const double pv[3] = {O[0] + tv * D[0], O[1] + tv * D[1], O[2] + tv * D[2]};
    // A near miss. With |∇f| ≤ √3·r / h the distance is at least |s_v|·h / (√3·r): beyond half the
    // footprint, no coverage (no gradient needed).
    if (std::abs(s_v) * hmin > 0.87 * cell_range * tv * pitch) continue;
    shade_hit(f, S.grid.dims, S.spacing, pv, dir, T.colour, rgb, g);
    gn = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(gn > 0)) continue;
    if (!near_surface(f, S, iso, pv, s_v, g, gn)) continue;
    const double x = std::abs(s_v) / gn, footprint = tv * pitch;
    if (x > half_voxel) continue;  // beyond the macro-cells' margin: not seen alike by every brick
    const double cover = 0.5 - x / footprint;
    if (cover <= 0) continue;
    // A rim seen at its point of closest approach is dark (n·d ≈ 0); the sub-rays that meet the
    // surface within the pixel meet it farther in, lighter: their mean (issue 41's dark rims in valleys).
    shade_near_miss_footprint(f, S.grid.dims, S.spacing, pv, dir, g, footprint, half_voxel, x, T.iso, T.colour, rgb);
    if (add(rgb, cover)) return std::max(j - 1, 0);
  }
  if (k0 + n - 1 == k_last && t_exit > t0 + double(k_last) * dt) {
    // The ray's last stretch in the domain, after its last sample.
    const float sl = s(n);
    double ta = t0 + double(k_last) * dt, tb = t_exit;
    const double se = interp_clamped(f, O[0] + tb * D[0], O[1] + tb * D[1], O[2] + tb * D[2]) - iso;
    if ((se < 0) != (sl < 0)) {
      double dpa = sl, dpb = se;
      double th = ta + (tb - ta) * (dpa / (dpa - dpb));
      const double vh = interp_clamped(f, O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]) - iso;
      if ((vh < 0) == (dpa < 0)) ta = th, dpa = vh;
      else tb = th, dpb = vh;
      if (dpa != dpb) th = ta + (tb - ta) * (dpa / (dpa - dpb));
      const double ph[3] = {O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]};
      alignas(16) float rgb[4];
      shade_hit(f, S.grid.dims, S.spacing, ph, dir, T.colour, rgb);
      add(rgb, 1.0);
      sliver.state = SliverEnd::closed;
      return n - 1;
    }
  }
  if (defer) {
    sliver.pending = true;
    sliver.pend_k = k0 + n - 1;
    sliver.pend_v[0] = v[n - 1], sliver.pend_v[1] = v[n];
    sliver.pend_ranged = range != nullptr;
    sliver.pend_range = range ? range[n - 1] : 0.0f;
  }
  return -1;
}

int resolve_pending_lane(const MarchPlan& S, const MarchTask& T, const FieldAcc& f, const RayPos& P, const double O[3],
                         const double D[3], const Vec3& dir, double t0, std::int64_t k_last, double t_exit, float tr_stop,
                         float* a, IsoSliver& sliver) {
  sliver.pending = false;
  // A block of one sample (pend_k; v[0] the sample before), its lane a candidate: the sample after it
  // is interpolated on demand, as before the lane waited.
  const float v[2] = {sliver.pend_v[0], sliver.pend_v[1]};
  const float range = sliver.pend_range;
  return march_iso_block_aa(S, T, f, P, O, D, dir, t0, sliver.pend_k, 1, v, sliver.pend_ranged ? &range : nullptr, 1u,
                            k_last, t_exit, tr_stop, a, sliver);
}

}  // namespace panoptes::render::march
