#include "render/reference_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "render/iso_shading.hpp"

namespace panoptes::render {

namespace {

float sample(const FieldView& f, float x, float y, float z) {
  const auto& d = f.grid.dims;
  // Positions are evaluated in float as the renderer does, then clamped into the data.
  float p[3] = {x, y, z};
  int c[3];
  float w[3];
  for (int a = 0; a < 3; ++a) {
    p[a] = std::clamp(p[a], 0.0f, float(d[a] - 1));
    c[a] = std::clamp(int(p[a]), 0, d[a] - 2);
    w[a] = p[a] - float(c[a]);
  }
  auto v = [&](int i, int j, int k) { return f.at(c[0] + i, c[1] + j, c[2] + k); };
  const float c00 = v(0, 0, 0) + w[0] * (v(1, 0, 0) - v(0, 0, 0));
  const float c10 = v(0, 1, 0) + w[0] * (v(1, 1, 0) - v(0, 1, 0));
  const float c01 = v(0, 0, 1) + w[0] * (v(1, 0, 1) - v(0, 0, 1));
  const float c11 = v(0, 1, 1) + w[0] * (v(1, 1, 1) - v(0, 1, 1));
  const float c0 = c00 + w[1] * (c10 - c00), c1 = c01 + w[1] * (c11 - c01);
  return c0 + w[2] * (c1 - c0);
}

}  // namespace

void render_reference(const camera::Camera& cam, std::span<const FieldView> fields, std::span<const TaskSpec> tasks,
                      std::span<PartialImage> out, const RenderOptions& opt) {
  if (out.size() != tasks.size())
    throw Error("reference renderer: " + std::to_string(tasks.size()) + " tasks but " + std::to_string(out.size()) +
                " output images");
  if (fields.empty()) throw Error("reference renderer: no fields given");
  const GridGeometry& g = fields[0].grid;
  for (const FieldView& f : fields)
    if (!(f.brick == Brick::whole(g)) || f.points.lo != Index3{0, 0, 0} || f.points.hi != g.dims)
      throw Error("reference renderer: fields must be whole-grid views");
  std::vector<TransferLut> l1(tasks.size()), l2(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const TaskSpec& t = tasks[i];
    if (t.kind != TaskKind::volume && t.kind != TaskKind::isosurface)
      throw Error("reference renderer: only volume and isosurface tasks are supported");
    auto check = [&](int f) {
      if (f < 0 || std::size_t(f) >= fields.size())
        throw Error("reference renderer: task refers to field " + std::to_string(f));
    };
    check(t.field);
    if (t.kind == TaskKind::isosurface) {
      if (!std::isfinite(t.isovalue)) throw Error("reference renderer: isovalue is not finite");
      continue;
    }
    l1[i] = TransferLut(t.tf, t.window.resolve(t.reference), opt.sample_distance);
    if (t.field2 >= 0) {
      check(t.field2);
      l2[i] = TransferLut(t.tf2, t.window2.resolve(t.reference2), opt.sample_distance);
    }
  }
  const int W = cam.width(), H = cam.height();
  for (PartialImage& o : out) o.reset(W, H, {0, 0, W, H});
  const double dt = opt.sample_distance * g.voxel();
  const float tr_stop = 1.0f - opt.termination_alpha;
#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const camera::Ray ray = cam.ray(x + 0.5, y + 0.5);
      double O[3], D[3], t0 = -INFINITY, t1 = INFINITY;
      bool hit = true;
      for (int a = 0; a < 3; ++a) {
        O[a] = (ray.origin[a] - g.origin[a]) / g.spacing[a];
        D[a] = ray.direction[a] / g.spacing[a];
        const double hi = double(g.dims[a] - 1);
        if (D[a] == 0) {
          hit = hit && O[a] >= 0 && O[a] <= hi;
          continue;
        }
        double ta = (0 - O[a]) / D[a], tb = (hi - O[a]) / D[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta), t1 = std::min(t1, tb);
      }
      t0 = std::max(t0, 0.0);
      if (!hit || !(t1 > t0)) continue;
      const std::int64_t last = std::int64_t(std::ceil((t1 - t0) / dt)) - 1;
      const double frac = (t1 - (t0 + double(last) * dt)) / dt;
      const float partial = frac < 1 - 1e-6 ? float(std::max(0.0, frac)) : 1.0f;
      // Positions from the sample index in float, as the renderer computes them.
      const float b[3] = {float(O[0] + t0 * D[0]), float(O[1] + t0 * D[1]), float(O[2] + t0 * D[2])};
      const float s[3] = {float(dt * D[0]), float(dt * D[1]), float(dt * D[2])};
      for (std::size_t i = 0; i < tasks.size(); ++i) {
        const TaskSpec& t = tasks[i];
        if (t.kind == TaskKind::isosurface) {
          // The first segment (sample k − 1 … k) whose ends lie on different sides of the isovalue:
          // linear estimate, one regula-falsi step, then the pre-issue-10 shading.
          const FieldView& f = fields[std::size_t(t.field)];
          const float iso = t.isovalue;
          float prev = sample(f, b[0], b[1], b[2]);
          float* dst = out[i].rgba_at(x, y);
          for (std::int64_t k = 1; k <= last; ++k) {
            const float fk = float(k);
            const float v = sample(f, b[0] + fk * s[0], b[1] + fk * s[1], b[2] + fk * s[2]);
            if ((prev - iso < 0) != (v - iso < 0)) {
              double ta = t0 + double(k - 1) * dt, tb = ta + dt;
              double dpa = prev - iso, dpb = v - iso;
              double th = ta + (tb - ta) * (dpa / (dpa - dpb));
              const double vh = sample(f, float(O[0] + th * D[0]), float(O[1] + th * D[1]), float(O[2] + th * D[2])) - iso;
              if ((vh < 0) == (dpa < 0)) ta = th, dpa = vh;
              else tb = th, dpb = vh;
              if (dpa != dpb) th = ta + (tb - ta) * (dpa / (dpa - dpb));
              const double ph[3] = {O[0] + th * D[0], O[1] + th * D[1], O[2] + th * D[2]};
              shade_isosurface_hit(f, ph, ray.direction, t.surface_colour, false, dst);
              break;
            }
            prev = v;
          }
          out[i].depth[std::size_t(y) * W + x] = float(t0);
          continue;
        }
        float c[3] = {0, 0, 0}, tr = 1;
        for (std::int64_t k = 0; k <= last; ++k) {
          const float fk = float(k);
          const float px = b[0] + fk * s[0], py = b[1] + fk * s[1], pz = b[2] + fk * s[2];
          const LutEntry& e1 = l1[i](sample(fields[std::size_t(t.field)], px, py, pz));
          float add[3], al;
          if (t.field2 < 0) {
            add[0] = e1.pr, add[1] = e1.pg, add[2] = e1.pb, al = e1.alpha;
            if (k == last && partial < 1) {
              const float an = al > 0 ? 1.0f - std::pow(1.0f - al, partial) : 0.0f;
              const float sf = al > 0 ? an / al : 0.0f;
              add[0] *= sf, add[1] *= sf, add[2] *= sf, al = an;
            }
          } else {
            const LutEntry& e2 = l2[i](sample(fields[std::size_t(t.field2)], px, py, pz));
            const float tau = e1.tau + e2.tau;
            if (tau <= 0) continue;
            al = 1.0f - (1.0f - e1.alpha) * (1.0f - e2.alpha);
            if (k == last && partial < 1) al = 1.0f - std::pow(1.0f - al, partial);
            const float w = al / tau;
            add[0] = w * (e1.tau * e1.r + e2.tau * e2.r);
            add[1] = w * (e1.tau * e1.g + e2.tau * e2.g);
            add[2] = w * (e1.tau * e1.b + e2.tau * e2.b);
          }
          for (int ch = 0; ch < 3; ++ch) c[ch] += tr * add[ch];
          tr *= 1.0f - al;
          if (tr <= tr_stop) break;
        }
        float* dst = out[i].rgba_at(x, y);
        dst[0] = c[0], dst[1] = c[1], dst[2] = c[2], dst[3] = 1.0f - tr;
        out[i].depth[std::size_t(y) * W + x] = float(t0);
      }
    }
}

}  // namespace panoptes::render
