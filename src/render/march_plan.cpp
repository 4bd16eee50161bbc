#include "render/march_plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace panoptes::render::march {

MarchPlan compile_march_plan(std::span<const PreparedField> fields, std::span<const TaskSpec> tasks,
                             const RenderOptions& opt) {
  const FieldView& f0 = fields[0].view;
  MarchPlan S;
  S.grid = f0.grid;
  S.brick = f0.brick;
  S.spacing = f0.grid.spacing;
  S.dt = opt.sample_distance * f0.grid.voxel();
  S.termination = opt.termination_alpha;
  S.mc = fields[0].cells.size();
  S.mcount = fields[0].cells.counts();

  // Fields read by the tasks get march slots (interpolated once per sample, whatever K is).
  std::vector<int> slot_of(fields.size(), -1);
  std::vector<int> field_of_slot;
  auto slot = [&](int f) {
    if (f < 0 || std::size_t(f) >= fields.size())
      throw Error("render: task refers to field " + std::to_string(f) + " but " + std::to_string(fields.size()) +
                  " fields were given");
    if (slot_of[std::size_t(f)] < 0) {
      slot_of[std::size_t(f)] = int(field_of_slot.size());
      field_of_slot.push_back(f);
      FieldAcc acc = make_acc(fields[std::size_t(f)].view);
      const CornerField& cf = fields[std::size_t(f)].corners;
      if (!cf.empty() && cf.lo() == fields[std::size_t(f)].view.points.lo) {
        acc.corners = cf.data();
        acc.ccx = cf.counts()[0];
        acc.ccxy = cf.counts()[0] * cf.counts()[1];
        acc.crec = cf.record();
        acc.qoff = cf.offset();
        acc.qscale = cf.scale();
      }
      S.acc.push_back(acc);
      S.cells.push_back(&fields[std::size_t(f)].cells);
    }
    return slot_of[std::size_t(f)];
  };

  std::vector<TransferLut>& luts = S.luts;
  std::vector<std::vector<MixEntry>>& mixes = S.mixes;
  std::vector<std::vector<VolRow>>& rows = S.rows;
  luts.resize(2 * tasks.size());
  mixes.resize(2 * tasks.size());
  rows.resize(tasks.size());
  S.rt.resize(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const TaskSpec& t = tasks[i];
    MarchTask& r = S.rt[i];
    const std::uint64_t bit = std::uint64_t(1) << i;
    auto bake = [&](const TransferFunction& tf, const ValueWindow& w, double ref, int which) -> TransferLut& {
      luts[2 * i + std::size_t(which)] = TransferLut(tf, w.resolve(ref), opt.sample_distance);
      return luts[2 * i + std::size_t(which)];
    };
    // The first field's slot and colour-map LUT: volumes and MIPs read them alike.
    auto first_field = [&]() -> const TransferLut& {
      r.kind = march_kind(t);
      r.s1 = slot(t.field);
      r.slots = 1u << r.s1;
      const TransferLut& l1 = bake(t.tf, t.window, t.reference, 0);
      r.lut1 = &l1.entry(0);
      r.lo1 = l1.lo(), r.sc1 = l1.scale(), r.last1 = float(l1.bins() - 1), r.abs1 = l1.absolute_value();
      return l1;
    };
    switch (t.kind) {
      case TaskKind::volume: {
        const TransferLut& l1 = first_field();
        if (t.field2 < 0) {
          rows[i] = vol_rows(l1);
          r.row1 = rows[i].data();
          S.volume1_mask |= bit;
        }
        if (t.field2 >= 0) {
          r.s2 = slot(t.field2);
          r.slots |= 1u << r.s2;
          const TransferLut& l2 = bake(t.tf2, t.window2, t.reference2, 1);
          r.lut2 = &l2.entry(0);
          r.lo2 = l2.lo(), r.sc2 = l2.scale(), r.last2 = float(l2.bins() - 1), r.abs2 = l2.absolute_value();
          mixes[2 * i] = mix_entries(l1);
          mixes[2 * i + 1] = mix_entries(l2);
          r.mix1 = mixes[2 * i].data();
          r.mix2 = mixes[2 * i + 1].data();
        }
        S.march_mask |= bit;
        break;
      }
      case TaskKind::isosurface:
        if (!std::isfinite(t.isovalue)) throw Error("render: isovalue is not finite");
        r.kind = march_kind(t);
        r.s1 = slot(t.field);
        r.slots = 1u << r.s1;
        r.iso = t.isovalue;
        r.colour[0] = t.surface_colour.r, r.colour[1] = t.surface_colour.g, r.colour[2] = t.surface_colour.b;
        S.march_mask |= bit;
        S.iso_mask |= bit;
        break;
      case TaskKind::slice: {
        if (t.slice_axis < 0 || t.slice_axis > 2)
          throw Error("render: slice axis " + std::to_string(t.slice_axis) + "; expected 0 (x), 1 (y) or 2 (z)");
        if (!(t.slice_opacity >= 0 && t.slice_opacity <= 1))
          throw Error("render: slice opacity " + std::to_string(t.slice_opacity) + "; expected [0, 1]");
        r.kind = march_kind(t);
        r.s1 = slot(t.field);
        const TransferLut& l1 = bake(t.tf, t.window, t.reference, 0);
        r.lut1 = &l1.entry(0);
        r.lo1 = l1.lo(), r.sc1 = l1.scale(), r.last1 = float(l1.bins() - 1), r.abs1 = l1.absolute_value();
        r.axis = t.slice_axis;
        const int a = t.slice_axis;
        r.plane = (t.slice_position - S.grid.origin[a]) / S.spacing[a];  // index coordinates
        r.opacity = t.slice_opacity;
        S.slices.push_back(int(i));
        break;
      }
      case TaskKind::mip: {
        // The colour map's LUT gives the window's coordinate of a value (lo, scale, |v|) and, at the
        // maximum's bin, the colour; its opacity is not used.
        first_field();
        S.march_mask |= bit;
        S.mip_mask |= bit;
        break;
      }
    }
    if (blend_of(t.kind) == Blend::max) S.max_mask |= bit;
  }
  if (S.acc.size() > 8) throw Error("render: tasks of one call read " + std::to_string(S.acc.size()) + " fields; at most 8");
  for (std::size_t s = 0; s < S.acc.size(); ++s) {
    if (S.acc[s].corners) S.corner_slots |= 1u << s;
    for (std::size_t u = 0; u < S.acc.size(); ++u)
      if (u != s && same_corner_layout(S.acc[s], S.acc[u])) S.corner_mates[s] |= 1u << u;
  }
  // A joint copy's partner is the only mate: their records share a cache line.
  for (std::size_t s = 0; s < S.acc.size(); ++s)
    for (std::size_t u = 0; u < S.acc.size(); ++u)
      if ((S.corner_mates[s] >> u & 1) && S.acc[s].crec == 16 &&
          (S.acc[u].corners == S.acc[s].corners + 8 || S.acc[s].corners == S.acc[u].corners + 8))
        S.corner_mates[s] = 1u << u;
  for (std::size_t i = 0; i < S.rt.size(); ++i)
    if ((S.march_mask >> i & 1) && S.rt[i].kind == MarchKind::volume1)
      S.volume1_on_slot[std::size_t(S.rt[i].s1)] |= std::uint64_t(1) << i;
  // The paper's mix (march_trio()): a two-field task on two corner copies of one layout, with a
  // single-field task on each of its fields.
  for (std::size_t i3 = 0; i3 < S.rt.size() && !S.trio_mask; ++i3) {
    const MarchTask& r3 = S.rt[i3];
    if (!(S.march_mask >> i3 & 1) || r3.kind != MarchKind::volume2 || r3.s1 == r3.s2) continue;
    if (!(S.corner_slots >> r3.s1 & 1) || !(S.corner_slots >> r3.s2 & 1) ||
        !(S.corner_mates[std::size_t(r3.s1)] >> r3.s2 & 1))
      continue;
    int i1 = -1, i2 = -1;
    for (std::size_t i = 0; i < S.rt.size(); ++i) {
      if (!(S.march_mask >> i & 1) || S.rt[i].kind != MarchKind::volume1) continue;
      if (i1 < 0 && S.rt[i].s1 == r3.s1) i1 = int(i);
      else if (i2 < 0 && S.rt[i].s1 == r3.s2) i2 = int(i);
    }
    if (i1 < 0 || i2 < 0) continue;
    S.trio[0] = i1, S.trio[1] = i2, S.trio[2] = int(i3), S.trio_a = r3.s1, S.trio_b = r3.s2;
    S.trio_mask = std::uint64_t(1) << i1 | std::uint64_t(1) << i2 | std::uint64_t(1) << i3;
  }
  // Macro-cells whose samples cannot reach a data face: cell index c0 − 1 … c1 readable with its
  // upper neighbour in every field (samples are placed within a small fraction of a voxel of their
  // macro-cell, so one cell of margin is plenty).
  for (int a = 0; a < 3; ++a) {
    int ilo = std::numeric_limits<int>::min(), ihi = std::numeric_limits<int>::max();
    for (const FieldAcc& f : S.acc) ilo = std::max(ilo, f.ilo[a]), ihi = std::min(ihi, f.ihi[a]);
    S.safe_lo[a] = S.mcount[a];
    S.safe_hi[a] = -1;
    for (int m = 0; m < S.mcount[a]; ++m) {
      const int c0 = S.brick.lo[a] + m * S.mc, c1 = std::min(c0 + S.mc, S.brick.hi[a]);
      if (c0 - 1 >= ilo && c1 <= ihi) S.safe_lo[a] = std::min(S.safe_lo[a], m), S.safe_hi[a] = m;
    }
  }

  // Per macro-cell: which tasks see anything there (volume: non-zero opacity somewhere in the
  // cell's value range; isosurface: the isovalue inside it).
  const int nmc = fields[0].cells.total();
  S.active.assign(std::size_t(nmc), 0);
  for (int m = 0; m < nmc; ++m) {
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      const MarchTask& r = S.rt[i];
      const std::uint64_t bit = std::uint64_t(1) << i;
      if (!(S.march_mask & bit)) continue;
      if (!opt.skip_empty) {
        bits |= bit;
        continue;
      }
      const MacroCells& c1 = *S.cells[std::size_t(r.s1)];
      if (r.kind == MarchKind::iso) {
        if (c1.min(m) <= r.iso && r.iso <= c1.max(m)) bits |= bit;
      } else if (r.kind == MarchKind::mip) {
        // A cell all of whose values lie at or below the window's low end can only give the
        // coordinate 0, where every ray's maximum starts: skipping it changes no maximum. (The
        // samples interpolate the float field, within the cell's range.)
        const float hi = r.abs1 ? std::max(std::fabs(c1.min(m)), std::fabs(c1.max(m))) : c1.max(m);
        if (!((hi - r.lo1) * r.sc1 <= 0)) bits |= bit;
      } else {
        // Quantized values may stray half a step outside the cell's float range.
        const float e1 = S.acc[std::size_t(r.s1)].qscale;
        bool vis = luts[2 * i].visible(c1.min(m) - e1, c1.max(m) + e1);
        if (!vis && r.kind == MarchKind::volume2) {
          const MacroCells& c2 = *S.cells[std::size_t(r.s2)];
          const float e2 = S.acc[std::size_t(r.s2)].qscale;
          vis = luts[2 * i + 1].visible(c2.min(m) - e2, c2.max(m) + e2);
        }
        if (vis) bits |= bit;
      }
    }
    S.active[std::size_t(m)] = bits;
  }
  {
    constexpr int kMaxExceptions = 16;  // beyond that the per-ray box tests would cost more than they save
    int n_exc = 0;
    for (int m = 0; m < nmc && n_exc <= kMaxExceptions; ++m) n_exc += S.active[std::size_t(m)] != S.march_mask;
    S.direct = S.march_mask && n_exc <= kMaxExceptions;
    if (S.direct)
      for (int m = 0; m < nmc; ++m) {
        if (S.active[std::size_t(m)] == S.march_mask) continue;
        const int mc3[3] = {m % S.mcount[0], (m / S.mcount[0]) % S.mcount[1], m / (S.mcount[0] * S.mcount[1])};
        std::array<double, 6> e;
        for (int a = 0; a < 3; ++a) {
          const int c0 = S.brick.lo[a] + mc3[a] * S.mc, c1 = std::min(c0 + S.mc, S.brick.hi[a]);
          e[std::size_t(a)] = c0 - 1.0;
          e[std::size_t(a) + 3] = c1 + 1.0;
        }
        S.exceptions.push_back(e);
      }
  }
  return S;
}

}  // namespace panoptes::render::march
