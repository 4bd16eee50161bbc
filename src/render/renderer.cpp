#include "render/ray_box.hpp"
#include "render/renderer.hpp"

// The renderer's pixel loop: the brick's screen footprint, tiles over OpenMP threads, each pixel's
// ray located against the domain and the brick, marched (ray_march.hpp) for the compiled task list
// (march_plan.hpp), slices intersected, and adaptive sampling (adaptive_sampling.hpp). The rooms
// of the march are listed in docs/rendering.md.
#include "render/adaptive_sampling.hpp"
#include "render/equirect_sampling.hpp"
#include "render/iso_edges.hpp"
#include "render/march_plan.hpp"
#include "render/ray_march.hpp"
#include "render/sample_blocks.hpp"
#include "render/tile_schedule.hpp"
#include "camera/pixel_rays.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <limits>
#include <cmath>
#include <string>
#include <vector>

#include <omp.h>

#include "core/error.hpp"

namespace panoptes::render {

namespace {

using march::MarchKind;
using march::MarchTask;

}  // namespace

RenderStats render_brick(const camera::Camera& cam, std::span<const PreparedField> fields,
                         std::span<const TaskSpec> tasks, std::span<PartialImage> out, const RenderOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  if (out.size() != tasks.size())
    throw Error("render: " + std::to_string(tasks.size()) + " tasks but " + std::to_string(out.size()) + " output images");
  if (fields.empty()) throw Error("render: no fields given");
  if (!(opt.sample_distance > 0 && opt.sample_distance <= 16))
    throw Error("render: sample distance " + std::to_string(opt.sample_distance) + " voxels; expected 0 < d <= 16");
  if (opt.tile < 1) throw Error("render: tile size " + std::to_string(opt.tile) + "; expected >= 1");
  if (opt.adaptive_tile < 1)
    throw Error("render: adaptive tile size " + std::to_string(opt.adaptive_tile) + "; expected >= 1");
  const FieldView& f0 = fields[0].view;
  for (const PreparedField& f : fields) {
    f.view.validate();
    if (f.view.grid.dims != f0.grid.dims || !(f.view.grid.origin == f0.grid.origin) ||
        !(f.view.grid.spacing == f0.grid.spacing) || !(f.view.brick == f0.brick) ||
        f.cells.size() != fields[0].cells.size() || f.cells.counts() != fields[0].cells.counts())
      throw Error("render: all fields of one call must share grid, brick and macro-cell size");
  }
  RenderStats stats;
  if (tasks.size() > std::size_t(kMaxTasksPerMarch)) {
    for (std::size_t g = 0; g < tasks.size(); g += kMaxTasksPerMarch) {
      const std::size_t n = std::min<std::size_t>(kMaxTasksPerMarch, tasks.size() - g);
      const RenderStats s = render_brick(cam, fields, tasks.subspan(g, n), out.subspan(g, n), opt);
      stats.rays = std::max(stats.rays, s.rays);
      stats.samples += s.samples;
      stats.marched_samples += s.marched_samples;
      stats.interpolated_pixels = std::max(stats.interpolated_pixels, s.interpolated_pixels);
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
  }

  march::MarchPlan plan = march::compile_march_plan(fields, tasks, opt);
  if (opt.iso_antialias && plan.iso_mask) plan.iso_aa_pitch = march::pixel_pitch(cam);
  const march::MarchPlan& S = plan;

  // The brick's screen footprint.
  const int W = cam.width(), H = cam.height();
  PixelRect rect{W, H, 0, 0};
  // An equirectangular image wraps around the camera: corner projections bound nothing, march every pixel.
  bool all = cam.projection() != camera::Projection::perspective;
  double cpx[8], cpy[8];
  for (int c = 0; c < 8 && !all; ++c) {
    Vec3 p;
    for (int a = 0; a < 3; ++a)
      p[a] = S.grid.origin[a] + ((c >> a) & 1 ? S.brick.hi[a] : S.brick.lo[a]) * S.spacing[a];
    double px, py;
    if (!cam.project(p, px, py)) {
      all = true;
      break;
    }
    cpx[c] = px, cpy[c] = py;
    rect.x0 = std::min(rect.x0, int(std::floor(std::max(px, -1.0))) - 1);
    rect.y0 = std::min(rect.y0, int(std::floor(std::max(py, -1.0))) - 1);
    rect.x1 = std::max(rect.x1, int(std::ceil(std::min(px, W + 1.0))) + 1);
    rect.y1 = std::max(rect.y1, int(std::ceil(std::min(py, H + 1.0))) + 1);
  }
  if (all) rect = {0, 0, W, H};
  // The brick's silhouette, for adaptive cells of misses (only when every corner projected).
  const Silhouette silhouette(cpx, cpy, all ? 0 : 8);
  // Anti-aliased isosurfaces of a brick that is not the whole domain carry their sliver state
  // (PartialImage::slivers): a grazing ray's entry may lie in a brick in front of its exit.
  const bool whole = S.brick.lo == Index3{0, 0, 0} &&
                     S.brick.hi == Index3{S.grid.dims[0] - 1, S.grid.dims[1] - 1, S.grid.dims[2] - 1};
  const std::uint64_t sliver_tasks = S.iso_aa_pitch > 0 && !whole ? S.iso_mask : 0;
  // Every pixel of the rect is written below (a miss as transparent, +∞): no clearing first.
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].slivers = sliver_tasks >> i & 1;
    out[i].resize(W, H, rect);
  }
  rect = out.empty() ? PixelRect{} : out[0].rect;
  if (tasks.empty()) return stats;

  // Equirectangular frames are sampled adaptively on the sphere (equirect_sampling.hpp) unless switched off.
  const bool sphere = opt.equirect_adaptive && cam.projection() == camera::Projection::equirectangular;
  if (sphere && !(opt.equirect_lattice_deg > 0 && opt.equirect_lattice_deg <= 90))
    throw Error("render: equirect lattice " + std::to_string(opt.equirect_lattice_deg) + " degrees; expected 0 < d <= 90");
  const bool adaptive = opt.adaptive || sphere;
  const int stride = sphere ? equirect_row_stride(opt.equirect_lattice_deg, W) : opt.adaptive_stride;
  // Adaptive frames march each tile's own lattice borders (tiles are independent), so small tiles
  // march many redundant rays: 16-pixel tiles put 5 lattice columns in every 16 pixels instead of 4.
  const int tile_w = sphere ? kEquirectTileWidth : adaptive ? opt.adaptive_tile : opt.tile;
  const int tile_h = sphere ? kEquirectTileHeight : adaptive ? opt.adaptive_tile : opt.tile;
  // Tiles lie on multiples of the tile edge in image coordinates (clipped to the rect), so the
  // bricks of a decomposition cut their footprints into the same tiles where they overlap: with
  // adaptive sampling their lattices, and so most refinement decisions, then coincide.
  const int tx_first = rect.x0 / tile_w, ty_first = rect.y0 / tile_h;
  const int ntx = rect.empty() ? 0 : (rect.x1 - 1) / tile_w - tx_first + 1;
  const int nty = rect.empty() ? 0 : (rect.y1 - 1) / tile_h - ty_first + 1;
  const int K = int(tasks.size());
  const double glo[3] = {0, 0, 0};
  const double ghi[3] = {double(S.grid.dims[0] - 1), double(S.grid.dims[1] - 1), double(S.grid.dims[2] - 1)};
  const double blo[3] = {double(S.brick.lo[0]), double(S.brick.lo[1]), double(S.brick.lo[2])};
  const double bhi[3] = {double(S.brick.hi[0]), double(S.brick.hi[1]), double(S.brick.hi[2])};
  if (opt.adaptive && opt.adaptive_stride < 2)
    throw Error("render: adaptive stride " + std::to_string(opt.adaptive_stride) + "; expected >= 2");
  const float tolerance = sphere ? opt.equirect_tolerance : opt.adaptive_tolerance;
  if (adaptive && (!(tolerance >= 0) || (!sphere && !(opt.adaptive_linear_tolerance >= 0))))
    throw Error(std::string("render: ") + (sphere ? "equirect" : "adaptive") + " tolerance " + std::to_string(tolerance) +
                " (linear " + std::to_string(opt.adaptive_linear_tolerance) + "); expected >= 0");
  std::uint64_t n_rays = 0, n_eff = 0, n_marched = 0, n_interpolated = 0;
  const std::uint64_t all_tasks = K == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << K) - 1;
  // Adaptive sampling: isosurfaces and slices are refined wherever any task is (their edges are thin),
  // and so are maxima: where the ray's maximum moves from one feature to another the image has a
  // crease, at other pixels in each brick than in the whole.
  std::uint64_t edge_tasks = S.max_mask;
  for (int i = 0; i < K; ++i)
    if (S.rt[std::size_t(i)].kind == MarchKind::iso || S.rt[std::size_t(i)].kind == MarchKind::slice)
      edge_tasks |= std::uint64_t(1) << i;

  // Where the ray of pixel (x, y) meets the domain and the brick; false when it misses the brick.
  // `face` (adaptive sampling's entry face, adaptive_sampling.hpp) is 1 + 4·axis + 2·global + side
  // of the plane that sets the entry depth (the brick's or the domain's, side 1 = its upper face),
  // 0 when none does (the camera inside) or the projection is not a perspective one.
  struct PixelRay {
    double O[3], D[3];  // origin and direction in index coordinates
    Vec3 dir;
    double t0, tg1, tb0, tb1;
    float depth;
    std::uint8_t face;
  };
  const bool planar = cam.projection() == camera::Projection::perspective;
  // Camera::ray of the rect's pixels from per-column and per-row terms (the same bits); the origin in
  // index coordinates is every ray's. The tables live per calling thread (reused capacity); the OpenMP
  // threads below share this one through the reference (a thread_local named inside the region would
  // be each thread's own, empty).
  thread_local camera::PixelRays caller_rays;
  const camera::PixelRays& rays = caller_rays;
  caller_rays.reset(cam, rect.x0, rect.y0, rect.x1, rect.y1);
  double O_index[3];
  for (int a = 0; a < 3; ++a) O_index[a] = (rays.origin()[a] - S.grid.origin[a]) / S.spacing[a];
  // One brick for the whole domain (one rank): its box is the domain's.
  const bool whole_domain = std::equal(blo, blo + 3, glo) && std::equal(bhi, bhi + 3, ghi);
  auto locate = [&](int x, int y, PixelRay& r) {
    r.dir = rays.direction(x, y);
    for (int a = 0; a < 3; ++a) {
      r.O[a] = O_index[a];
      r.D[a] = r.dir[a] / S.spacing[a];
    }
    double tg0;
    int ag, ab;
    if (!ray_box(r.O, r.D, glo, ghi, tg0, r.tg1, ag)) return false;
    r.t0 = std::max(tg0, 0.0);
    if (r.tg1 <= r.t0) return false;
    if (whole_domain) {  // the brick's slab test would repeat the domain's, bit for bit
      r.tb0 = tg0, r.tb1 = r.tg1, ab = ag;
    } else if (!ray_box(r.O, r.D, blo, bhi, r.tb0, r.tb1, ab)) {
      return false;
    }
    r.face = 0;
    if (r.tb0 >= r.t0 && ab >= 0) r.face = std::uint8_t(1 + 4 * ab + (r.D[ab] < 0));
    else if (tg0 > 0 && ag >= 0) r.face = std::uint8_t(3 + 4 * ag + (r.D[ag] < 0));
    r.tb0 = std::max(r.tb0, r.t0);
    r.tb1 = std::min(r.tb1, r.tg1);
    if (r.tb1 < r.tb0) return false;
    // A camera inside the domain may sit exactly on a face this brick shares with its upper neighbour
    // (e.g. a lattice node on an MPI cut): a ray leaving through that face has its t = 0 sample owned
    // by the neighbour (half-open extents), so this brick's part lies just behind it in depth.
    r.depth = float(r.tb0);
    if (r.tb0 == 0) {
      r.face = 0;
      for (int a = 0; a < 3; ++a)
        if (r.O[a] == bhi[a] && bhi[a] != ghi[a] && r.D[a] < 0) r.depth = std::nextafter(0.0f, 1.0f);
    }
    if (!planar) r.face = 0;
    return true;
  };
  // An eye strictly inside the brick: every ray meets it at t = 0 (depth 0, no face), as locate() finds
  // with its slab tests, which an interpolated pixel of a 360° frame from inside would spend most on.
  bool eye_in_brick = true;
  for (int a = 0; a < 3; ++a) eye_in_brick = eye_in_brick && O_index[a] > blo[a] && O_index[a] < bhi[a];
  // The entry depth of pixel (x, y) whose ray is known to enter through plane `face` (as locate()
  // reported for the corners of its adaptive cell): that plane's term of the slab test, bit for bit.
  auto face_depth = [&](int x, int y, std::uint8_t face) {
    const int f = face - 1, a = f >> 2;
    const double plane = f & 2 ? (f & 1 ? ghi[a] : glo[a]) : (f & 1 ? bhi[a] : blo[a]);
    const double D = rays.direction(x, y, a) / S.spacing[a];
    return float((plane - O_index[a]) / D);
  };
  // Marches a located ray for every task and writes pixel (x, y) of every image.
  // Marches a located ray for the tasks in `tasks` and writes their pixel (x, y); every image's depth.
  auto shade = [&](int x, int y, const PixelRay& r, std::uint64_t tasks, float (*acc)[4], march::IsoSliver* sl,
                   std::uint64_t& eff, std::uint64_t& marched) {
    for (int i = 0; i < K; ++i) acc[i][0] = acc[i][1] = acc[i][2] = acc[i][3] = 0;
    const std::uint64_t aa_iso = S.iso_aa_pitch > 0 ? S.iso_mask & tasks : 0;
    for (std::uint64_t m = aa_iso; m; m &= m - 1) {  // a task not marched: no event
      sl[std::countr_zero(m)].state = SliverEnd::pass;
      sl[std::countr_zero(m)].has_alt = false;
    }
    if (S.march_mask & tasks)
      march::march_ray(S, r.O, r.D, r.dir, r.t0, r.tg1, r.tb0, r.tb1, tasks, acc, eff, marched, sl);
    for (int i : S.slices) {
      if (!(tasks >> i & 1)) continue;
      const MarchTask& rt = S.rt[std::size_t(i)];
      const int a = rt.axis;
      if (r.D[a] == 0) continue;
      const double t = (rt.plane - r.O[a]) / r.D[a];
      if (!(t >= r.t0)) continue;
      double p[3] = {r.O[0] + t * r.D[0], r.O[1] + t * r.D[1], r.O[2] + t * r.D[2]};
      p[a] = rt.plane;
      bool in = true;  // the march's ownership rule: half-open, closed at the domain's upper faces
      for (int b = 0; b < 3; ++b)
        in = in && p[b] >= blo[b] && (p[b] < bhi[b] || (p[b] == bhi[b] && bhi[b] == ghi[b]));
      if (!in) continue;
      const float v = march::interp_clamped(S.acc[std::size_t(rt.s1)], p[0], p[1], p[2]);
      const LutEntry& e = rt.lut1[march::lut_bin(v, rt.lo1, rt.sc1, rt.last1, rt.abs1)];
      acc[i][0] = e.r * rt.opacity, acc[i][1] = e.g * rt.opacity, acc[i][2] = e.b * rt.opacity, acc[i][3] = rt.opacity;
    }
    for (int i = 0; i < K; ++i) {
      PartialImage& o = out[std::size_t(i)];
      float& depth = o.depth[std::size_t(y - o.rect.y0) * o.rect.width() + (x - o.rect.x0)];
      if (S.mip_mask >> i & 1) {
        // A max-blend image's depth is its order key (partial_image.hpp), written only when the
        // task is marched here: an adaptive pass marching other tasks must not overwrite it. (The
        // blend, not the kind, decides what the depth holds: a MIP joined by over would be ordered
        // by its entry depth, and its bricks' images would not join to the single-brick image.)
        const bool keyed = S.max_mask >> i & 1;
        if (!(tasks >> i & 1)) {
          if (!keyed) depth = r.depth;
          continue;
        }
        float* dst = o.rgba_at(x, y);
        if (acc[i][3] > 0) {  // samples in this brick: the colour map at the maximum, opaque
          const MarchTask& rt = S.rt[std::size_t(i)];
          const LutEntry& e = rt.lut1[int(acc[i][0])];
          dst[0] = e.r, dst[1] = e.g, dst[2] = e.b, dst[3] = 1;
          depth = keyed ? max_key_depth(acc[i][0]) : r.depth;
        } else {
          dst[0] = dst[1] = dst[2] = dst[3] = 0;
          depth = keyed ? PartialImage::kNoDepth : r.depth;
        }
        continue;
      }
      if (tasks >> i & 1) {
        float* dst = o.rgba_at(x, y);
        if (aa_iso >> i & 1) {
          // acc: the colour if a sliver is open at the brick's front; the pixel's colour is the one
          // if none is (the state at the ray's start), which differs after an exit before any entry.
          const float* c = sl[i].has_alt ? sl[i].alt : acc[i];
          dst[0] = c[0], dst[1] = c[1], dst[2] = c[2], dst[3] = c[3];
          if (o.slivers) {
            const std::size_t p = o.index(x, y);
            std::copy_n(acc[i], 4, &o.rgba_open[4 * p]);
            o.sliver_end[p] = sl[i].state;
          }
        } else {
          dst[0] = acc[i][0], dst[1] = acc[i][1], dst[2] = acc[i][2], dst[3] = acc[i][3];
        }
      }
      depth = r.depth;
    }
  };

  auto clear_pixel = [&](int x, int y) {  // a miss
    for (int i = 0; i < K; ++i) {
      PartialImage& o = out[std::size_t(i)];
      float* dst = o.rgba_at(x, y);
      dst[0] = dst[1] = dst[2] = dst[3] = 0;
      o.depth[std::size_t(y - o.rect.y0) * o.rect.width() + (x - o.rect.x0)] = PartialImage::kNoDepth;
      if (o.slivers) {
        const std::size_t p = o.index(x, y);
        std::fill_n(&o.rgba_open[4 * p], 4, 0.0f);
        o.sliver_end[p] = SliverEnd::pass;
      }
    }
  };

  const int chunk = tile_chunk(ntx, ntx * nty, omp_get_max_threads());
#pragma omp parallel reduction(+ : n_rays, n_eff, n_marched, n_interpolated)
  {
    alignas(64) float acc[kMaxTasksPerMarch][4];
    march::IsoSliver sliver[kMaxTasksPerMarch];
    AdaptiveTile refiner(stride, tolerance, sphere ? 0.0f : opt.adaptive_linear_tolerance);
#pragma omp for schedule(dynamic, chunk)
    for (int ti = 0; ti < ntx * nty; ++ti) {
      const int tx0 = std::max(rect.x0, (tx_first + ti % ntx) * tile_w), ty0 = std::max(rect.y0, (ty_first + ti / ntx) * tile_h);
      const int tx1 = std::min((tx_first + ti % ntx + 1) * tile_w, rect.x1), ty1 = std::min((ty_first + ti / ntx + 1) * tile_h, rect.y1);
      PixelRay r;
      if (!adaptive) {
        for (int y = ty0; y < ty1; ++y)
          for (int x = tx0; x < tx1; ++x) {
            if (!locate(x, y, r)) {
              clear_pixel(x, y);
              continue;
            }
            ++n_rays;
            shade(x, y, r, all_tasks, acc, sliver, n_eff, n_marched);
          }
        continue;
      }
      auto march = [&](int x, int y, std::uint64_t tasks) -> std::uint8_t {
        if (locate(x, y, r)) {
          ++n_rays;
          shade(x, y, r, tasks, acc, sliver, n_eff, n_marched);
          return r.face;
        }
        clear_pixel(x, y);
        return std::uint8_t(0);
      };
      auto depth_of = [&](int x, int y, std::uint8_t face) {
        if (eye_in_brick) return 0.0f;  // what locate() gives every ray from there, without the slab tests
        if (face) return face_depth(x, y, face);
        return locate(x, y, r) ? r.depth : PartialImage::kNoDepth;
      };
      const std::uint64_t before = refiner.interpolated();
      const int columns = sphere ? equirect_column_stride(stride, H, ty0, ty1, kEquirectTileWidth / 2) : 0;
      refiner.run(PixelRect{tx0, ty0, tx1, ty1}, out, march, depth_of, edge_tasks, silhouette.empty() ? nullptr : &silhouette,
                  columns, S.max_mask);
      n_interpolated += refiner.interpolated() - before;
    }
  }
  stats.rays = n_rays;
  stats.samples = n_eff;
  stats.marched_samples = n_marched;
  stats.interpolated_pixels = n_interpolated;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}


std::vector<QuantizationRange> quantization_ranges(int n_fields, std::span<const TaskSpec> tasks) {
  // Past a window's ends a transfer function is constant, so a sample there looks the same whatever
  // the value. The margin of 64 window widths keeps trilinear samples between a clamped corner and
  // its neighbours within 1/64 of a cell of where the true field crosses the window's end, and leaves
  // a quantization step of 1/500 of the window (half a step: 1/4 of an 8-bit colour level).
  constexpr double kMargin = 64;
  std::vector<double> lo(std::size_t(n_fields), std::numeric_limits<double>::infinity()),
      hi(std::size_t(n_fields), -std::numeric_limits<double>::infinity());
  auto add = [&](int f, double a, double b) {
    if (f < 0 || f >= n_fields) return;  // prepare_fields() names the bad index
    lo[std::size_t(f)] = std::min(lo[std::size_t(f)], a);
    hi[std::size_t(f)] = std::max(hi[std::size_t(f)], b);
  };
  auto add_window = [&](int f, const TransferFunction& tf, const ValueWindow& w, double reference) {
    const ValueWindow r = w.resolve(reference);
    const double m = kMargin * (r.hi - r.lo);
    if (tf.absolute_value) {
      const double b = std::max(std::abs(r.lo), std::abs(r.hi)) + m;
      add(f, -b, b);
    } else {
      add(f, r.lo - m, r.hi + m);
    }
  };
  for (const TaskSpec& t : tasks) {
    switch (t.kind) {
      case TaskKind::volume:
        add_window(t.field, t.tf, t.window, t.reference);
        if (t.field2 >= 0) add_window(t.field2, t.tf2, t.window2, t.reference2);
        break;
      case TaskKind::mip:  // reads the march's samples of its field, as a volume does
        add_window(t.field, t.tf, t.window, t.reference);
        break;
      case TaskKind::isosurface:  // the crossing must stay on its side of the clamp
        add(t.field, t.isovalue, t.isovalue);
        break;
      default:  // slices read the float field
        break;
    }
  }
  std::vector<QuantizationRange> out(static_cast<std::size_t>(n_fields));
  for (std::size_t f = 0; f < out.size(); ++f)
    if (lo[f] <= hi[f]) {
      // Rounded outwards to float, so that the window's own ends are inside.
      out[f].lo = std::nextafter(float(lo[f]), -std::numeric_limits<float>::infinity());
      out[f].hi = std::nextafter(float(hi[f]), std::numeric_limits<float>::infinity());
    }
  return out;
}

std::vector<PreparedField> prepare_fields(std::span<const FieldView> views, std::span<const TaskSpec> tasks,
                                          int macro_cell_size) {
  const int n = int(views.size());
  auto check = [&](int f) {
    if (f < 0 || f >= n)
      throw Error("prepare_fields: a task refers to field " + std::to_string(f) + " but " + std::to_string(n) +
                  " fields were given");
    return f;
  };
  std::vector<char> volume(std::size_t(n), 0);
  std::vector<std::pair<int, int>> wanted;  // two-field volume tasks first, then in order of use
  std::vector<int> order;
  for (const TaskSpec& t : tasks) {
    if (t.kind != TaskKind::volume) {
      check(t.field);
      continue;
    }
    const int a = check(t.field);
    if (!volume[std::size_t(a)]) volume[std::size_t(a)] = 1, order.push_back(a);
    if (t.field2 >= 0) {
      const int b = check(t.field2);
      if (!volume[std::size_t(b)]) volume[std::size_t(b)] = 1, order.push_back(b);
      if (a != b) wanted.emplace_back(a, b);
    }
  }
  for (std::size_t i = 0; i + 1 < order.size(); ++i) wanted.emplace_back(order[i], order[i + 1]);
  std::vector<int> partner(std::size_t(n), -1);
  auto same_range = [&](int a, int b) {
    return views[std::size_t(a)].points.lo == views[std::size_t(b)].points.lo &&
           views[std::size_t(a)].points.hi == views[std::size_t(b)].points.hi;
  };
  for (const auto& [a, b] : wanted)
    if (partner[std::size_t(a)] < 0 && partner[std::size_t(b)] < 0 && same_range(a, b))
      partner[std::size_t(a)] = b, partner[std::size_t(b)] = a;
  const std::vector<QuantizationRange> keep = quantization_ranges(n, tasks);
  std::vector<PreparedField> out(static_cast<std::size_t>(n));
  for (int f = 0; f < n; ++f) {
    const FieldView& v = views[std::size_t(f)];
    const int p = partner[std::size_t(f)];
    if (p >= 0 && p < f) continue;  // built with its partner
    if (p >= 0) {
      auto [cf, cp] = CornerField::joint(v, views[std::size_t(p)], keep[std::size_t(f)], keep[std::size_t(p)]);
      out[std::size_t(f)] = PreparedField(v, std::move(cf), macro_cell_size);
      out[std::size_t(p)] = PreparedField(views[std::size_t(p)], std::move(cp), macro_cell_size);
    } else {
      out[std::size_t(f)] =
          PreparedField(v, macro_cell_size, volume[std::size_t(f)] ? FieldCopy::corners16 : FieldCopy::none,
                        keep[std::size_t(f)]);
    }
  }
  return out;
}

}  // namespace panoptes::render
