#include "render/ray_march.hpp"

// Sections, in order: the samples a brick owns (brick_samples); one ray's march (class RayMarch: the
// run dispatch run(), the macro-cell walk walk_macro_cells(), the loops run_trio(), run_sweep() and
// general_block(), where every kind has its case); march_ray(), which sets up and finishes the
// accumulators (the transmittance convention of partial_image.hpp).

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

#include "render/compositing_kernels.hpp"
#include "render/iso_edges.hpp"
#include "render/iso_shading.hpp"
#include "render/march_runs.hpp"
#include "render/sample_blocks.hpp"

namespace panoptes::render::march {
namespace {

// ceil(q) for |q| < 2^62 without a libm call; truncation toward zero already is the ceiling for
// negative q. Runs between macro-cell faces are short, so this is on the per-macro-cell path.
inline std::int64_t ceil_index(double q) {
  const std::int64_t n = std::int64_t(q);
  return n + (double(n) < q);
}

// The samples k_s … k_e of the ray that this brick owns (k ≥ 0 from t0, step S.dt); false when
// there are none. Sets kg_last, the ray's last sample in the whole domain.
bool brick_samples(const MarchPlan& S, const double O[3], const double D[3], double t0, double tg1, double tb0,
                   double tb1, std::int64_t& ks, std::int64_t& ke, std::int64_t& kg_last) {
  const double dt = S.dt;
  const Brick& B = S.brick;
  kg_last = std::int64_t(std::ceil((tg1 - t0) / dt)) - 1;
  ks = std::max<std::int64_t>(0, std::int64_t(std::ceil((tb0 - t0) / dt)) - 1);
  ke = std::min(kg_last, std::int64_t(std::floor((tb1 - t0) / dt)) + 1);
  // Exact membership, computed identically by every brick of a decomposition: half-open [lo, hi),
  // closed at the upper faces of the global domain so every sample of the domain has one owner.
  // Samples 0 … kg_last lie in the domain by construction; clamping undoes rounding at its faces.
  auto inside = [&](std::int64_t k) {
    const double t = t0 + double(k) * dt;
    for (int a = 0; a < 3; ++a) {
      const double p = std::clamp(O[a] + t * D[a], 0.0, double(S.grid.dims[a] - 1));
      if (!(p >= B.lo[a] && (p < B.hi[a] || (p == B.hi[a] && B.hi[a] == S.grid.dims[a] - 1)))) return false;
    }
    return true;
  };
  while (ks <= ke && !inside(ks)) ++ks;
  while (ke >= ks && !inside(ke)) --ke;
  return ks <= ke;
}

// One ray's march after its sample range is known: the per-ray state (live tasks, accumulators,
// the block buffers) and the two steps, run dispatch (run(): which loop marches a run of samples
// for the tasks live in it) and the macro-cell walk (walk_macro_cells(): which runs there are).
class RayMarch {
 public:
  RayMarch(const MarchPlan& plan, const double* origin, const double* direction, const Vec3& world_dir, double t_0,
           double tg1, std::int64_t ke, std::int64_t kg_last, std::uint64_t tasks, float (*accumulators)[4],
           std::uint64_t& marched_samples, IsoSliver* iso_sliver)
      : S(plan), O(origin), D(direction), dir(world_dir), t0(t_0), dt(plan.dt), live(tasks), acc(accumulators),
        marched(marched_samples), k_last(kg_last), t_exit(tg1), sliver(iso_sliver) {
    for (std::size_t s = 0; s < S.acc.size(); ++s) fa[s] = S.acc[s];
    // The last sample of the ray in the whole domain stands for a shorter segment.
    if (ke == kg_last) {
      const double f = (tg1 - (t0 + double(kg_last) * dt)) / dt;
      if (f < 1 - 1e-6) {
        k_partial = kg_last;
        partial = float(std::max(0.0, f));
      }
    }
    P = RayPos{float(O[0] + t0 * D[0]), float(O[1] + t0 * D[1]), float(O[2] + t0 * D[2]),
               float(dt * D[0]),        float(dt * D[1]),        float(dt * D[2])};
    tr_stop = 1.0f - S.termination;
  }

  // Run dispatch: marches samples kb … kend, in consecutive macro-cells whose live tasks are all
  // `mask`; `safe`: the cells lie inside the data with a one-cell margin, so interpolation needs no
  // clamps. One volume task takes march_volume1(), the paper's mix march_trio(), a sweep on one
  // field march_volumes(), anything else the general block.
  void run(std::int64_t kb, std::int64_t kend, std::uint64_t mask, bool safe) {
    for (std::int64_t k0 = kb; k0 <= kend;) {
      const std::uint64_t lm = mask & live;
      if (!lm) break;
      if (single_volume(lm)) {
        // Fast path: one volume task left (from the start, or the others terminated).
        const int i = std::countr_zero(lm);
        const MarchTask& T = S.rt[std::size_t(i)];
        bool opaque = false;
        const std::int64_t kk =
            march_volume1(fa[T.s1], T, acc[i], k0, kend, P, safe, k_partial, partial, tr_stop, opaque);
        if (opaque) live &= ~(std::uint64_t(1) << i);
        marched += std::uint64_t(kk - k0);
        prev_valid = 0;  // values were not kept (no isosurface task is live here)
        return;
      }
      if (S.trio_mask && !(lm & ~S.trio_mask)) {
        const std::int64_t kk = run_trio(lm, k0, kend);
        if (kk > k0) {
          k0 = kk;
          continue;
        }
      }
      if (!(lm & ~S.volume1_mask) &&
          !(lm & ~S.volume1_on_slot[std::size_t(S.rt[std::size_t(std::countr_zero(lm))].s1)]) &&
          std::popcount(lm) <= kMaxSweep) {
        k0 = run_sweep(lm, k0, kend, safe);
        continue;
      }
      general_block(lm, k0, kend, safe);
      k0 += kBlock;
    }
  }

  // After the march: anti-aliased isosurface tasks still live whose last block left a lane pending
  // (IsoSliver::pending) look at it now, before the accumulators are read.
  void resolve_pending_lanes() {
    if (!(S.iso_aa_pitch > 0)) return;
    for (std::uint64_t m = live & S.iso_mask; m; m &= m - 1) {
      const int i = std::countr_zero(m);
      if (!sliver[i].pending) continue;
      const MarchTask& T = S.rt[std::size_t(i)];
      if (resolve_pending_lane(S, T, fa[T.s1], P, O, D, dir, t0, k_last, t_exit, tr_stop, acc[i], sliver[i]) >= 0)
        live &= ~(std::uint64_t(1) << i);
    }
  }

  // Dense scenes (S.direct): whether the ray's samples ks … ke meet none of the plan's exception
  // boxes, so that one run over the whole ray is the merged walk.
  bool clear_of_exceptions(std::int64_t ks, std::int64_t ke) const {
    // The ray's samples lie within [t0 + (ks − 1)·dt, t0 + (ke + 1)·dt]; the walk visits only cells
    // that stretch meets, and the boxes are grown by a voxel, so a miss is conservative.
    const double ta = t0 + double(ks - 1) * dt, tb = t0 + double(ke + 1) * dt;
    bool clear = true;
    if (!S.exceptions.empty()) {
      // Reciprocals instead of six divisions per box: rounding does not matter, the boxes have a voxel of margin.
      double inv[3];
      for (int a = 0; a < 3; ++a) inv[a] = D[a] != 0 ? 1.0 / D[a] : 0.0;
      for (const auto& e : S.exceptions) {
        double u0 = ta, u1 = tb;
        for (int a = 0; a < 3 && u0 <= u1; ++a) {
          if (D[a] == 0) {
            if (O[a] < e[std::size_t(a)] || O[a] > e[std::size_t(a) + 3]) u0 = INFINITY;
            continue;
          }
          double v0 = (e[std::size_t(a)] - O[a]) * inv[a], v1 = (e[std::size_t(a) + 3] - O[a]) * inv[a];
          if (v0 > v1) std::swap(v0, v1);
          u0 = std::max(u0, v0), u1 = std::min(u1, v1);
        }
        if (u0 <= u1) {
          clear = false;
          break;
        }
      }
    }
    return clear;
  }

  // The macro-cell walk: queues runs of visible cells and hands them to run().
  void walk_macro_cells(std::int64_t ks, std::int64_t ke) {
    const Brick& B = S.brick;
    // 3-D DDA over the macro-cells (Amanatides–Woo): per cell only a compare, an add and a mask load;
    // sample indices are computed only for cells that some live task can see, so a run of empty
    // cells costs a few cycles each. The walk starts in the cell of sample ks (clamped to the brick).
    const int M = S.mc;
    const double inv_m = 1.0 / M, inv_dt = 1.0 / dt;
    const double t_ks = t0 + double(ks) * dt, t_ke = t0 + double(ke) * dt;
    const double q_max = double(ke) + 1;  // caps q before the integer conversion
    int mi[3], dstep[3];
    double tmax[3], tdelta[3];
    const std::int64_t lin[3] = {1, S.mcount[0], std::int64_t(S.mcount[0]) * S.mcount[1]};
    std::int64_t lstep[3];
    for (int a = 0; a < 3; ++a) {
      const double p = O[a] + t_ks * D[a];
      mi[a] = std::clamp(int((p - B.lo[a]) * inv_m), 0, S.mcount[a] - 1);
      const double c0 = B.lo[a] + double(mi[a]) * M, c1 = std::min(c0 + M, double(B.hi[a]));
      if (D[a] > 0) {
        tmax[a] = (c1 - O[a]) / D[a];
        tdelta[a] = M / D[a];
        dstep[a] = 1;
      } else if (D[a] < 0) {
        tmax[a] = (c0 - O[a]) / D[a];
        tdelta[a] = -M / D[a];
        dstep[a] = -1;
      } else {
        tmax[a] = INFINITY;
        tdelta[a] = 0;
        dstep[a] = 0;
      }
      lstep[a] = dstep[a] * lin[a];
    }
    std::int64_t idx = mi[0] + lin[1] * mi[1] + lin[2] * mi[2];
    const std::uint64_t* active = S.active.data();
    const std::uint64_t iso_mask = S.iso_mask;
    std::int64_t k = ks;      // first sample not yet marched, queued or skipped
    double tenter = t0 - dt;  // the first cell starts before sample ks
    // Consecutive visible macro-cells with the same live tasks are merged into one queued run
    // [rb, re]: fewer, longer runs waste fewer lanes of the 8-sample blocks and less per-run setup.
    // The samples and their order are the same, so merging cannot change an image. A merged general
    // run drops to the fast path as soon as one volume task is left (see run()).
    // The queued run's last sample is computed only when it ends (from the exit of its last cell),
    // so a dense stretch of visible cells costs the walk a compare and a mask load per cell.
    bool queued = false;
    std::int64_t rb = 0;
    double rexit = 0;
    bool rlast = false, rsafe = true;
    std::uint64_t rmask = 0;
    auto flush = [&](bool to_end) {
      // Samples rounded past the last macro-cell's exit stay with it (its margin covers them).
      const std::int64_t re =
          to_end || rlast ? ke : std::min(ke, ceil_index(std::min((rexit - t0) * inv_dt, q_max)) - 1);
      queued = false;
      if (rb <= re) {
        run(rb, re, rmask, rsafe);
        k = re + 1;
      }
    };
    // The walk's state per axis in scalars (tx, ty, tz; cells left nx, ny, nz), not in arrays indexed
    // by the axis: indexed arrays live on the stack, and every cell paid store-to-load round trips.
    double tx = tmax[0], ty = tmax[1], tz = tmax[2];
    const double dx = tdelta[0], dy = tdelta[1], dz = tdelta[2];
    const std::int64_t lx = lstep[0], ly = lstep[1], lz = lstep[2];
    // Cells left to enter along each axis after the current one (a zero direction never steps).
    auto left = [&](int a) { return dstep[a] > 0 ? S.mcount[a] - 1 - mi[a] : dstep[a] < 0 ? mi[a] : 0; };
    int nx = left(0), ny = left(1), nz = left(2);
    int mx = mi[0], my = mi[1], mz = mi[2];
    const int sx = dstep[0], sy = dstep[1], sz = dstep[2];
    for (;;) {
      double texit;
      bool last_cell;
      int a;
      if (tx < ty) {
        if (tx < tz) a = 0, texit = tx, last_cell = nx == 0;
        else a = 2, texit = tz, last_cell = nz == 0;
      } else {
        if (ty < tz) a = 1, texit = ty, last_cell = ny == 0;
        else a = 2, texit = tz, last_cell = nz == 0;
      }
      std::uint64_t mask = active[idx] & live;
      if (queued && mask != rmask) {
        if (mask && !((mask ^ rmask) & iso_mask)) {
          // Other volume tasks see something here: the run goes on for the union. A volume task marched
          // through a cell where it sees nothing composites exact no-ops (α = 0: colour += T·0, T ·= 1),
          // so its image keeps its bits, and the march is not cut into short runs with setup each.
          rmask |= mask;
        } else {  // the queued run ends here: march it (live may shrink)
          flush(false);
          if (!live || k > ke) break;
          mask = active[idx] & live;
        }
      }
      if (mask) {
        const bool safe = mx >= S.safe_lo[0] && mx <= S.safe_hi[0] && my >= S.safe_lo[1] && my <= S.safe_hi[1] &&
                          mz >= S.safe_lo[2] && mz <= S.safe_hi[2];
        if (queued) {  // same tasks: the cell's samples continue the queued run
          rsafe = rsafe && safe;
        } else {
          queued = true, rmask = mask, rsafe = safe;
          rb = std::max(k, ceil_index(std::min((tenter - t0) * inv_dt, q_max)));
        }
        rexit = texit, rlast = last_cell;
        if (texit > t_ke) {  // every remaining sample lies in this cell
          flush(true);
          break;
        }
      } else {
        prev_valid = 0;  // the samples of this cell are skipped
        if (texit > t_ke) break;  // every remaining sample lies in this empty cell
      }
      if (last_cell) break;
      if (a == 0) --nx, mx += sx, idx += lx, tx += dx;
      else if (a == 1) --ny, my += sy, idx += ly, ty += dy;
      else --nz, mz += sz, idx += lz, tz += dz;
      tenter = texit;
    }
    if (queued) flush(false);
  }

 private:
  bool single_volume(std::uint64_t m) const {
    return m && !(m & (m - 1)) && S.rt[std::size_t(std::countr_zero(m))].kind == MarchKind::volume1;
  }

  // The paper's mix, or what is left of it (a single volume task took the fast path). Returns one
  // past the last sample consumed (k0 when march_trio() left the block to the general path).
  std::int64_t run_trio(std::uint64_t lm, std::int64_t k0, std::int64_t kend) {
      unsigned sub = 0, done = 0;
      for (int q = 0; q < 3; ++q) sub |= unsigned(lm >> S.trio[q] & 1) << q;
      const MarchTask &T1 = S.rt[std::size_t(S.trio[0])], &T2 = S.rt[std::size_t(S.trio[1])],
                   &T3 = S.rt[std::size_t(S.trio[2])];
      float *a1 = acc[S.trio[0]], *a2 = acc[S.trio[1]], *a3 = acc[S.trio[2]];
      const FieldAcc &fA = fa[S.trio_a], &fB = fa[S.trio_b];
      std::int64_t kk = k0;
      switch (sub) {
        case 7: kk = march_trio<7>(fA, fB, T1, T2, T3, a1, a2, a3, k0, kend, P, k_partial, partial, tr_stop, done); break;
        case 3: kk = march_trio<3>(fA, fB, T1, T2, T3, a1, a2, a3, k0, kend, P, k_partial, partial, tr_stop, done); break;
        case 5: kk = march_trio<5>(fA, fB, T1, T2, T3, a1, a2, a3, k0, kend, P, k_partial, partial, tr_stop, done); break;
        case 6: kk = march_trio<6>(fA, fB, T1, T2, T3, a1, a2, a3, k0, kend, P, k_partial, partial, tr_stop, done); break;
        case 4: kk = march_trio<4>(fA, fB, T1, T2, T3, a1, a2, a3, k0, kend, P, k_partial, partial, tr_stop, done); break;
        default: break;
      }
      for (int q = 0; q < 3; ++q)
        if (done >> q & 1) live &= ~(std::uint64_t(1) << S.trio[q]);
      marched += std::uint64_t(kk - k0);
      prev_valid = 0;
    return kk;
  }

  // Single-field volume tasks on one field only (two or more: one took the fast path), at most
  // kMaxSweep. Returns one past the last sample marched.
  std::int64_t run_sweep(std::uint64_t lm, std::int64_t k0, std::int64_t kend, bool safe) {
    const int G = std::popcount(lm);
      const MarchTask* T[kMaxSweep];
      float* as[kMaxSweep];
      int ids[kMaxSweep], g = 0;
      for (std::uint64_t m = lm; m; m &= m - 1, ++g) {
        ids[g] = std::countr_zero(m);
        T[g] = &S.rt[std::size_t(ids[g])], as[g] = acc[ids[g]];
      }
      const FieldAcc& f = fa[T[0]->s1];
      unsigned done = 0;
      std::int64_t kk = k0;
      [&]<int... Q>(std::integer_sequence<int, Q...>) {
        ((G == Q + 2 ? (kk = march_volumes<Q + 2>(f, T, as, k0, kend, P, safe, k_partial, partial, tr_stop, done), 0)
                     : 0),
         ...);
      }(std::make_integer_sequence<int, kMaxSweep - 1>{});
      for (int q = 0; q < G; ++q)
        if (done >> q & 1) live &= ~(std::uint64_t(1) << ids[q]);
      marched += std::uint64_t(kk - k0);
      prev_valid = 0;
    return kk;
  }

  // One block (samples k0 … k0 + kBlock − 1, at most kend) of any task mix.
  void general_block(std::uint64_t lm, std::int64_t k0, std::int64_t kend, bool safe) {
    // General path: the block's values of every field a live task reads, then the live tasks
    // consume the whole block — single-field volume tasks four at a time with their chains
    // interleaved (composite_group()), the others task after task. Per task these are the
    // operations of a one-task march in the same sample order, so one march for K tasks gives
    // every task's image bit for bit.
    const int n = int(std::min<std::int64_t>(kBlock, kend - k0 + 1));
    // Slots read by live volume tasks (values for classification: vq) and by live isosurface
    // tasks (float values with the previous sample: vb).
    std::uint32_t vmask = 0, smask = 0;
    for (std::uint64_t m = lm; m; m &= m - 1) {
      const MarchTask& T = S.rt[std::size_t(std::countr_zero(m))];
      // Isosurfaces and maxima read the float field (vb), volumes their classification values (vq).
      (T.kind == MarchKind::iso || T.kind == MarchKind::mip ? smask : vmask) |= T.slots;
    }
    // Anti-aliased isosurfaces also take each sample's cell range from the gathers (near misses).
    const std::uint32_t rmask = S.iso_aa_pitch > 0 && (lm & S.iso_mask) ? smask : 0;
    ranged = 0;
    // Corner-copy fields of one layout in pairs: one geometry for both (S.corner_mates, found at
    // setup; a joint copy's partner first: their records share a cache line and one prefetch).
    std::uint32_t cm = vmask & S.corner_slots;
    if (k0 + kPrefetchBlocks * kBlock <= kend) {
      for (std::uint32_t pm = cm; pm;) {
        const int s = std::countr_zero(pm);
        pm &= pm - 1;
        const std::uint32_t mates = pm & S.corner_mates[std::size_t(s)];
        if (mates) {
          const int s2 = std::countr_zero(mates);
          pm &= ~(1u << s2);
          const FieldAcc* const fs[2] = {&fa[s], &fa[s2]};
          prefetch_block_corners<2>(fs, P, k0 + kPrefetchBlocks * kBlock);
        } else {
          const FieldAcc* const fs[1] = {&fa[s]};
          prefetch_block_corners<1>(fs, P, k0 + kPrefetchBlocks * kBlock);
        }
      }
    }
    while (cm) {
      const int s = std::countr_zero(cm);
      cm &= cm - 1;
      const std::uint32_t mates = cm & S.corner_mates[std::size_t(s)];
      if (mates) {
        const int s2 = std::countr_zero(mates);
        cm &= ~(1u << s2);
        const FieldAcc* const fs[2] = {&fa[s], &fa[s2]};
        float* const vs[2] = {vq[s], vq[s2]};
        interp_block_corners_n<2>(fs, P, k0, n, vs);
      } else {
        interp_block_corners(fa[s], P, k0, n, vq[s]);
      }
    }
    for (std::uint32_t m = vmask & ~S.corner_slots; m; m &= m - 1) {
      const int s = std::countr_zero(m);
      if (smask >> s & 1)
        vq_from_vb |= 1u << s;  // the same float values as the isosurface's: copied below
      else
        interp_block(fa[s], P, k0, n, safe, vq[s]);
    }
    for (std::uint32_t m = smask; m; m &= m - 1) {
      const int s = std::countr_zero(m);
      if (!(prev_valid >> s & 1) && k0 > 0) {
        // The sample before this block (maybe in the previous brick: within the ghost layers).
        const float fk = float(k0 - 1);
        vb[s][0] = interp_clamped(fa[s], P.bx + fk * P.sx, P.by + fk * P.sy, P.bz + fk * P.sz);
        prev_valid |= 1u << s;
      }
      if (rmask >> s & 1) {
        if (interp_block(fa[s], P, k0, n, safe, &vb[s][1], vr[s])) ranged |= 1u << s;
      } else {
        interp_block(fa[s], P, k0, n, safe, &vb[s][1]);
      }
    }
    for (std::uint32_t m = vq_from_vb; m; m &= m - 1) {
      const int s = std::countr_zero(m);
      std::copy_n(&vb[s][1], kBlock, vq[s]);
    }
    vq_from_vb = 0;
    int used = 0;  // lanes consumed by the task that went furthest
    auto task_done = [&](int i, int stop) {
      if (stop >= 0) {
        live &= ~(std::uint64_t(1) << i);
        used = std::max(used, stop + 1);
      } else {
        used = n;
      }
    };
    // Single-field volume tasks in groups of up to four, their chains interleaved.
    for (std::uint64_t m = lm & S.volume1_mask; m;) {
      constexpr int kGroup = 4;
      int ids[kGroup], g = 0;
      const VolRow* luts[kGroup];
      float* as[kGroup];
      alignas(32) int bins[kGroup][kBlock];
      int stops[kGroup];
      for (; m && g < kGroup; m &= m - 1, ++g) {
        const int i = std::countr_zero(m);
        const MarchTask& T = S.rt[std::size_t(i)];
        ids[g] = i, luts[g] = T.row1, as[g] = acc[i];
        lut_bin_block<kRowShift>(vq[T.s1], T.lo1, T.sc1, T.last1, T.abs1, bins[g]);
      }
      switch (g) {
        case 1: composite_group<1>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
        case 2: composite_group<2>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
        case 3: composite_group<3>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
        default: composite_group<4>(luts, bins, as, stops, n, k0, k_partial, partial, tr_stop); break;
      }
      for (int q = 0; q < g; ++q) task_done(ids[q], stops[q]);
    }
    for (std::uint64_t m = lm & ~S.volume1_mask; m; m &= m - 1) {
      const int i = std::countr_zero(m);
      const MarchTask& T = S.rt[std::size_t(i)];
      float* a = acc[i];
      int stop = -1;
      switch (T.kind) {
        case MarchKind::volume1:  // composited above, in groups
          break;
        case MarchKind::volume2: {
          alignas(32) int bin1[kBlock], bin2[kBlock];
          lut_bin_block<kMixShift>(vq[T.s1], T.lo1, T.sc1, T.last1, T.abs1, bin1);
          lut_bin_block<kMixShift>(vq[T.s2], T.lo2, T.sc2, T.last2, T.abs2, bin2);
          stop = composite_volume2(T.mix1, T.mix2, bin1, bin2, n, k0, k_partial, partial, tr_stop, a);
          break;
        }
        case MarchKind::iso: {
          const float* v = vb[T.s1];
          const int l0 = (prev_valid >> T.s1 & 1) ? 0 : 1;
          if (S.iso_aa_pitch > 0) {
            const float* range = ranged >> T.s1 & 1 ? vr[T.s1] : nullptr;
            const unsigned cand = iso_aa_candidates(v, range, n, l0 == 0, T.iso);
            if (cand || sliver[i].pending || k0 + n - 1 == k_last)
              stop = march_iso_block_aa(S, T, fa[T.s1], P, O, D, dir, t0, k0, n, v, range, cand, k_last, t_exit, tr_stop, a,
                                        sliver[i]);
            break;
          }
          // Lanes whose segment (sample l − 1 … l) changes sign, found for the whole block at once.
          unsigned cross = 0;
#ifdef PANOPTES_RENDER_AVX2
          {
            const __m256 iso = _mm256_set1_ps(T.iso), zero = _mm256_setzero_ps();
            const BlockNeighbours w = block_neighbours(v);
            const __m256 sp = _mm256_cmp_ps(_mm256_sub_ps(w.before, iso), zero, _CMP_LT_OQ);
            const __m256 sn = _mm256_cmp_ps(_mm256_sub_ps(w.at, iso), zero, _CMP_LT_OQ);
            cross = unsigned(_mm256_movemask_ps(_mm256_xor_ps(sp, sn)));
          }
#else
          for (int l = 0; l < kBlock; ++l) cross |= unsigned((v[l] - T.iso < 0) != (v[l + 1] - T.iso < 0)) << l;
#endif
          cross &= ((1u << n) - 1) & ~((1u << l0) - 1);
          if (cross) {
            const int l = std::countr_zero(cross);
            const float d = v[l + 1] - T.iso, dp = v[l] - T.iso;
            // First crossing between samples kk − 1 and kk: linear estimate, one regula-falsi step.
            const std::int64_t kk = k0 + l;
            const FieldAcc& f = fa[T.s1];
            double ta = t0 + double(kk - 1) * dt, tb = ta + dt;
            double dpa = dp, dpb = d;
            double th = ta + (tb - ta) * (dpa / (dpa - dpb));
            const double vh = interp_clamped(f, O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]) - T.iso;
            if ((vh < 0) == (dpa < 0)) ta = th, dpa = vh;
            else tb = th, dpb = vh;
            if (dpa != dpb) th = ta + (tb - ta) * (dpa / (dpa - dpb));
            const double ph[3] = {O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]};
            shade_hit(f, S.grid.dims, S.spacing, ph, dir, T.colour, a);
            a[3] = 0;  // opaque: transmittance 0
            stop = l;
          }
          break;
        }
        case MarchKind::mip: {
          // The running maximum of the window's coordinate (lut_bin()'s u before truncation) in
          // a[0]; lane 3 only flags that the ray has samples here (march_ray()). NaN never wins.
          const float* v = vb[T.s1] + 1;
          float m = a[0];
          for (int l = 0; l < n; ++l) {
            const float u = ((T.abs1 ? std::fabs(v[l]) : v[l]) - T.lo1) * T.sc1;
            m = u > m ? u : m;
          }
          a[0] = m < T.last1 ? m : T.last1;
          if (a[0] >= T.last1) stop = n - 1;  // the window's top: nothing further can change the pixel
          break;
        }
        case MarchKind::slice:
          break;
      }
      task_done(i, stop);
    }
    marched += std::uint64_t(used);
    for (std::uint32_t m = smask; m; m &= m - 1) {
      const int s = std::countr_zero(m);
      vb[s][0] = vb[s][n];
    }
    prev_valid = smask;
  }

  const MarchPlan& S;
  const double* O;
  const double* D;
  const Vec3& dir;
  const double t0, dt;
  std::int64_t k_partial = -1;
  float partial = 1;
  RayPos P{};
  float tr_stop = 0;
  std::uint64_t live;
  float (*acc)[4];
  std::uint64_t& marched;
  FieldAcc fa[8];  // local copies: no aliasing with the accumulators, so no reloads per sample
  // vb[s][0] holds slot s's value at the sample before the current block, vb[s][1 + l] the block's
  // values; prev_valid: slots whose vb[s][0] is that previous sample (isosurface crossings need it).
  alignas(32) float vb[8][2 * kBlock];
  alignas(32) float vq[8][kBlock];
  alignas(32) float vr[8][kBlock];  // per slot: the cell range of each sample of the block (when `ranged`)
  std::uint32_t ranged = 0;
  std::uint32_t prev_valid = 0, vq_from_vb = 0;
  const std::int64_t k_last;  // the ray's last sample in the domain, and where it leaves the domain
  const double t_exit;        // (isosurface anti-aliasing looks at the stretch between them)
  IsoSliver* sliver;          // per isosurface task with anti-aliasing: its sliver state (iso_edges.hpp)
};

}  // namespace

void march_ray(const MarchPlan& S, const double O[3], const double D[3], const Vec3& dir, double t0, double tg1,
               double tb0, double tb1, std::uint64_t tasks, float (*acc)[4], std::uint64_t& effective,
               std::uint64_t& marched, IsoSliver* sliver) {
  const std::uint64_t mm = S.march_mask & tasks;  // the march tasks of this ray
  std::int64_t ks, ke, kg_last;
  if (!brick_samples(S, O, D, t0, tg1, tb0, tb1, ks, ke, kg_last)) return;
  effective += std::uint64_t(ke - ks + 1);
  // During the march acc[i][3] holds the TRANSMITTANCE T = 1 − α: the loop-carried chain per
  // sample is then one multiply, T ← T·(1 − α_s), and colour accumulates as C ← C + T·c_s·α_s.
  // (partial_image.hpp states the convention.) A MIP task keeps its running maximum in
  // acc[i][0], from the window's low end (0): cells below it are skipped, so a ray that sees only
  // them still has its maximum 0.
  for (std::uint64_t m = mm; m; m &= m - 1) acc[std::countr_zero(m)][3] = 1.0f;
  for (std::uint64_t m = mm & S.mip_mask; m; m &= m - 1) acc[std::countr_zero(m)][0] = 0.0f;
  // Anti-aliased isosurfaces: the brick that owns the ray's first sample knows that no sliver is
  // open where the ray enters it; the others learn it from the bricks in front when compositing.
  const std::uint64_t aa_iso = S.iso_aa_pitch > 0 ? mm & S.iso_mask : 0;
  for (std::uint64_t m = aa_iso; m; m &= m - 1) {
    IsoSliver& sl = sliver[std::countr_zero(m)];
    sl.state = ks == 0 ? SliverEnd::closed : SliverEnd::pass;
    sl.has_alt = false;
    sl.pending = false;
  }
  RayMarch ray(S, O, D, dir, t0, tg1, ke, kg_last, mm, acc, marched, sliver);
  if (S.direct && ray.clear_of_exceptions(ks, ke)) {
    // One run over the whole ray: the samples and their order are those of the merged walk, so
    // images are the same bits; `safe` = false only means clamped indices (same bits, see interp()).
    ray.run(ks, ke, mm, false);
  } else {
    ray.walk_macro_cells(ks, ke);
  }
  ray.resolve_pending_lanes();
  for (std::uint64_t m = mm & ~S.mip_mask; m; m &= m - 1) {
    float* a = acc[std::countr_zero(m)];
    a[3] = 1.0f - a[3];  // transmittance back to opacity
  }
  for (std::uint64_t m = aa_iso; m; m &= m - 1) {
    IsoSliver& sl = sliver[std::countr_zero(m)];
    if (sl.has_alt) sl.alt[3] = 1.0f - sl.alt[3];
  }
  // MIP tasks keep a[3] = 1: the ray has samples in this brick (the pixel loop colours them).
}

}  // namespace panoptes::render::march
