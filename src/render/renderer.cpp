#include "render/renderer.hpp"

#include "render/adaptive_sampling.hpp"
#include "render/iso_shading.hpp"
#include "camera/pixel_rays.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <limits>
#include <cmath>
#include <string>
#include <vector>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#define PANOPTES_RENDER_AVX2 1
#endif

#include "core/error.hpp"

namespace panoptes::render {

TaskSpec TaskSpec::volume(int field, TransferFunction tf, ValueWindow window, double reference) {
  TaskSpec t;
  t.kind = TaskKind::volume;
  t.field = field;
  t.tf = std::move(tf);
  t.window = window;
  t.reference = reference;
  return t;
}

TaskSpec TaskSpec::volume2(int field, TransferFunction tf, ValueWindow window, int field2, TransferFunction tf2,
                           ValueWindow window2, double reference, double reference2) {
  TaskSpec t = volume(field, std::move(tf), window, reference);
  t.field2 = field2;
  t.tf2 = std::move(tf2);
  t.window2 = window2;
  t.reference2 = reference2;
  return t;
}

TaskSpec TaskSpec::isosurface(int field, float isovalue, Rgb colour) {
  TaskSpec t;
  t.kind = TaskKind::isosurface;
  t.field = field;
  t.isovalue = isovalue;
  t.surface_colour = colour;
  return t;
}

TaskSpec TaskSpec::slice(int field, int axis, double position, TransferFunction colour_map, ValueWindow window,
                         double reference) {
  TaskSpec t;
  t.kind = TaskKind::slice;
  t.field = field;
  t.slice_axis = axis;
  t.slice_position = position;
  t.tf = std::move(colour_map);
  t.window = window;
  t.reference = reference;
  return t;
}

namespace {

// Raw access to one field for the hot loop: global point (i, j, k) is data[off0 + i·sx + j·sy + k·sz].
struct FieldAcc {
  const float* data;
  std::int64_t sx, sy, sz, off0;
  int ilo[3], ihi[3];    // clamp range of a cell's lower corner: [points.lo, points.hi − 2]
  float plo[3], phi[3];  // clamp range of positions: [points.lo, points.hi − 1]
  // Every element offset from the point points.lo fits a signed 32-bit lane and strides are
  // non-negative: the vectorized interpolation may gather with 32-bit indices.
  bool gather32 = false;
  // The field's CornerField (nullptr without one): volume classification reads it; isosurfaces,
  // slices and shading read the float field.
  const std::uint16_t* corners = nullptr;
  std::int32_t ccx = 0, ccxy = 0;  // corner records per row / per slice
  std::int32_t crec = 8;           // uint16 per cell record (16: two fields interleaved)
  float qoff = 0, qscale = 0;      // value = qoff + qscale·q
};

FieldAcc make_acc(const FieldView& v) {
  FieldAcc a;
  a.data = v.data;
  a.sx = v.stride[0];
  a.sy = v.stride[1];
  a.sz = v.stride[2];
  a.off0 = -(v.points.lo[0] * a.sx + v.points.lo[1] * a.sy + v.points.lo[2] * a.sz);
  for (int k = 0; k < 3; ++k) {
    a.ilo[k] = v.points.lo[k];
    a.ihi[k] = std::max(v.points.lo[k], v.points.hi[k] - 2);
    a.plo[k] = float(v.points.lo[k]);
    a.phi[k] = float(v.points.hi[k] - 1);
  }
  std::int64_t max_off = 0;
  bool nonneg = true;
  for (int k = 0; k < 3; ++k) {
    nonneg = nonneg && v.stride[std::size_t(k)] >= 0;
    max_off += std::int64_t(v.points.hi[k] - v.points.lo[k] - 1) * v.stride[std::size_t(k)];
  }
  a.gather32 = nonneg && max_off + a.sx + a.sy + a.sz < (std::int64_t(1) << 31);
  return a;
}

// Trilinear interpolation at index-space position (x, y, z). With kClamp the cell index is clamped
// so float rounding at the data's faces can never read outside it; macro-cells that lie at least
// one cell inside the data on every side use kClamp = false (the march knows which, see
// Shared::safe_lo/hi), which saves six min/max per field and sample. Both variants compute the same
// bits whenever the clamp would not change the index, so images do not depend on which one ran.
template <bool kClamp = true>
inline float interp(const FieldAcc& f, float x, float y, float z) {
  int i = int(x), j = int(y), k = int(z);
  if constexpr (kClamp) {
    i = std::min(std::max(i, f.ilo[0]), f.ihi[0]);
    j = std::min(std::max(j, f.ilo[1]), f.ihi[1]);
    k = std::min(std::max(k, f.ilo[2]), f.ihi[2]);
  }
  const float fx = x - float(i), fy = y - float(j), fz = z - float(k);
  const float* c = f.data + (f.off0 + i * f.sx + j * f.sy + k * f.sz);
  const std::int64_t sx = f.sx, sy = f.sy, sz = f.sz;
  const float c00 = c[0] + fx * (c[sx] - c[0]);
  const float c10 = c[sy] + fx * (c[sy + sx] - c[sy]);
  const float c01 = c[sz] + fx * (c[sz + sx] - c[sz]);
  const float c11 = c[sz + sy] + fx * (c[sz + sy + sx] - c[sz + sy]);
  const float c0 = c00 + fy * (c10 - c00);
  const float c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

// Interpolation at an arbitrary position (clamped into the data): off the hot path.
inline float interp_clamped(const FieldAcc& f, float x, float y, float z) {
  return interp(f, std::clamp(x, f.plo[0], f.phi[0]), std::clamp(y, f.plo[1], f.phi[1]),
                std::clamp(z, f.plo[2], f.phi[2]));
}
inline float interp_clamped(const FieldAcc& f, double x, double y, double z) {
  return interp_clamped(f, float(x), float(y), float(z));
}

enum class RtKind : std::uint8_t { volume1, volume2, iso, slice };

// A single-field volume task's LUT row for the march (see vol_rows()).
struct alignas(16) VolRow {
  float pr, pg, pb, om;
};

// A LUT row of one field of a two-field volume task (see composite_volume2()): τ·rgb, τ and 1 − α.
struct alignas(32) MixEntry {
  float tr, tg, tb, tau;
  float om;
};

constexpr int kRowShift = 4, kMixShift = 5;  // log2 of sizeof(VolRow), sizeof(MixEntry)
static_assert(sizeof(VolRow) == 1 << kRowShift && sizeof(MixEntry) == 1 << kMixShift);

template <class Row>
inline const Row& row_at(const Row* table, int byte_offset) {
  return *reinterpret_cast<const Row*>(reinterpret_cast<const char*>(table) + byte_offset);
}

std::vector<MixEntry> mix_entries(const TransferLut& lut) {
  std::vector<MixEntry> m(std::size_t(lut.bins()));
  for (int b = 0; b < lut.bins(); ++b) {
    const LutEntry& e = lut.entry(b);
    m[std::size_t(b)] = {e.tau * e.r, e.tau * e.g, e.tau * e.b, e.tau, 1.0f - e.alpha};
  }
  return m;
}

// A task prepared for the hot loop: field slots, LUT pointers and windows, isovalue, slice plane.
struct TaskRt {
  RtKind kind;
  int s1 = 0, s2 = 0;  // slots in the march's field list
  std::uint32_t slots = 0;  // bit mask of the slots the march reads for this task
  const LutEntry* lut1 = nullptr;
  const LutEntry* lut2 = nullptr;
  const VolRow* row1 = nullptr;    // volume1: the rows of lut1 as VolRow
  const MixEntry* mix1 = nullptr;  // volume2: the rows of lut1 and lut2 as MixEntry
  const MixEntry* mix2 = nullptr;
  float lo1 = 0, sc1 = 1, last1 = 0, lo2 = 0, sc2 = 1, last2 = 0;
  bool abs1 = false, abs2 = false;
  float iso = 0;
  float colour[3] = {0, 0, 0};
  int axis = 2;
  double plane = 0;  // slice plane in index coordinates
  float opacity = 1;
};

inline int lut_bin(float v, float lo, float sc, float last, bool absv) {
  if (absv) v = std::fabs(v);
  float u = (v - lo) * sc;
  u = u > 0 ? u : 0.0f;
  u = u < last ? u : last;
  return int(u);
}

// Ray–box intersection in index space; returns false when the ray misses. `axis` receives the axis
// of the plane where the ray enters (-1 when t0 stays −∞); that plane is lo[axis] when
// D[axis] > 0, else hi[axis], and t0 is exactly (plane − O[axis]) / D[axis].
inline bool slab(const double O[3], const double D[3], const double lo[3], const double hi[3], double& t0, double& t1,
                 int& axis) {
  t0 = -INFINITY;
  t1 = INFINITY;
  axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (D[a] == 0) {
      if (O[a] < lo[a] || O[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - O[a]) / D[a], tb = (hi[a] - O[a]) / D[a];
    if (ta > tb) std::swap(ta, tb);
    if (t0 < ta) t0 = ta, axis = a;  // the value of std::max(t0, ta)
    t1 = std::min(t1, tb);
  }
  return t1 >= t0;
}

struct Shared {
  const camera::Camera* cam;
  GridGeometry grid;
  Brick brick;
  std::vector<FieldAcc> acc;  // per march slot
  std::vector<const MacroCells*> cells;
  // Slots read from a corner copy, and per slot the other slots of the same corner layout.
  std::uint32_t corner_slots = 0;
  std::array<std::uint32_t, 8> corner_mates{};
  std::vector<TaskRt> rt;
  std::vector<std::uint64_t> active;  // per macro-cell: tasks with something visible in it
  std::uint64_t march_mask = 0, iso_mask = 0, volume1_mask = 0;
  // The paper's mix on one corner layout: volume1 tasks trio[0] (slot trio_a) and trio[1] (slot
  // trio_b) and the volume2 task trio[2] reading (trio_a, trio_b); trio_mask = 0 when absent.
  std::uint64_t trio_mask = 0;
  int trio[3] = {0, 0, 0}, trio_a = 0, trio_b = 0;
  // Per field slot: the single-field volume tasks reading it (march_volumes(): several transfer
  // functions or windows of one field).
  std::array<std::uint64_t, 8> volume1_on_slot{};
  // Dense scenes: (nearly) every macro-cell is visible to every march task. A ray that meets none
  // of the few cells that are not (`exceptions`: their boxes in index space, grown by one voxel) would
  // have its walk merge all its cells into one run, so the march skips the walk and runs [ks, ke].
  bool direct = false;
  std::vector<std::array<double, 6>> exceptions;  // lo xyz, hi xyz
  std::vector<int> slices;
  double dt = 0;
  float termination = 0.998f;
  int mc = 8;
  Index3 mcount{};
  // Macro-cells mi with safe_lo ≤ mi ≤ safe_hi on every axis lie at least one cell inside the data
  // of every field: their samples (even rounded one ulp outside) need no index clamps.
  int safe_lo[3] = {0, 0, 0}, safe_hi[3] = {-1, -1, -1};
  PartialImage* out = nullptr;  // first of rt.size() outputs
  Vec3 spacing;
};

// Headlight shading of an isosurface hit from its gradient g (field units per world unit): diffuse
// 0.15 + 0.85·|n·l|, specular 0.25·|n·l|^32, two-sided; a zero gradient counts as facing the camera.
// `squarings`: |n·l|^32 by five squarings (the renderer) instead of std::pow (the pre-issue-10
// formula, kept for the reference renderer); they differ by a few ulps of a double.
inline void shade_from_gradient(const double g[3], const Vec3& dir, const float colour[3], bool squarings, float* a) {
  const Vec3 n = normalize(Vec3{g[0], g[1], g[2]});
  double ndl = std::abs(dot(n, dir));  // headlight: light comes from the camera; two-sided
  if (norm(n) == 0) ndl = 1;
  double p32 = ndl;
  if (squarings) {
    for (int i = 0; i < 5; ++i) p32 *= p32;
  } else {
    p32 = std::pow(ndl, 32.0);
  }
  const float diffuse = float(0.15 + 0.85 * ndl);
  const float spec = float(0.25 * p32);
  for (int k = 0; k < 3; ++k) a[k] = std::min(1.0f, colour[k] * diffuse + spec);
  a[3] = 1.0f;
}

// The positions of the central differences at p: ±0.5 voxel per axis, one-sided at the domain's
// faces. q[2·ax] = p − 0.5·e_ax, q[2·ax + 1] = p + 0.5·e_ax; h[ax] = their distance in world units.
inline void gradient_points(const double p[3], const Index3& dims, const Vec3& spacing, double (*q)[3], double h[3]) {
  for (int ax = 0; ax < 3; ++ax) {
    double* q0 = q[2 * ax];
    double* q1 = q[2 * ax + 1];
    for (int b = 0; b < 3; ++b) q0[b] = q1[b] = p[b];
    q1[ax] = std::min(q1[ax] + 0.5, double(dims[ax] - 1));
    q0[ax] = std::max(q0[ax] - 0.5, 0.0);
    h[ax] = (q1[ax] - q0[ax]) * spacing[ax];
  }
}

#ifdef PANOPTES_RENDER_AVX2
// The trilinear field at 8 index-space positions (cell indices clamped into the data): eight AVX2
// gathers with 32-bit offsets and seven lerps. Shared by the march's sample blocks and the
// isosurface hit's gradient points, so both evaluate the field with the same operations.
inline __m256 trilinear8(const FieldAcc& f, __m256 x, __m256 y, __m256 z) {
  auto cell = [](__m256 p, int lo, int hi) {
    return _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(p), _mm256_set1_epi32(lo)), _mm256_set1_epi32(hi));
  };
  const __m256i i = cell(x, f.ilo[0], f.ihi[0]), j = cell(y, f.ilo[1], f.ihi[1]), k = cell(z, f.ilo[2], f.ihi[2]);
  const __m256 fx = _mm256_sub_ps(x, _mm256_cvtepi32_ps(i));
  const __m256 fy = _mm256_sub_ps(y, _mm256_cvtepi32_ps(j));
  const __m256 fz = _mm256_sub_ps(z, _mm256_cvtepi32_ps(k));
  // Offsets from the point points.lo (= ilo), so they stay small whatever the brick's place.
  const int sx = int(f.sx), sy = int(f.sy), sz = int(f.sz);
  const __m256i off = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_mullo_epi32(_mm256_sub_epi32(i, _mm256_set1_epi32(f.ilo[0])), _mm256_set1_epi32(sx)),
                       _mm256_mullo_epi32(_mm256_sub_epi32(j, _mm256_set1_epi32(f.ilo[1])), _mm256_set1_epi32(sy))),
      _mm256_mullo_epi32(_mm256_sub_epi32(k, _mm256_set1_epi32(f.ilo[2])), _mm256_set1_epi32(sz)));
  const float* d = f.data;
  const __m256 c000 = _mm256_i32gather_ps(d, off, 4), c100 = _mm256_i32gather_ps(d + sx, off, 4);
  const __m256 c010 = _mm256_i32gather_ps(d + sy, off, 4), c110 = _mm256_i32gather_ps(d + sy + sx, off, 4);
  const __m256 c001 = _mm256_i32gather_ps(d + sz, off, 4), c101 = _mm256_i32gather_ps(d + sz + sx, off, 4);
  const __m256 c011 = _mm256_i32gather_ps(d + sz + sy, off, 4), c111 = _mm256_i32gather_ps(d + sz + sy + sx, off, 4);
  const __m256 c00 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c100, c000), c000);
  const __m256 c10 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c110, c010), c010);
  const __m256 c01 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c101, c001), c001);
  const __m256 c11 = _mm256_fmadd_ps(fx, _mm256_sub_ps(c111, c011), c011);
  const __m256 c0 = _mm256_fmadd_ps(fy, _mm256_sub_ps(c10, c00), c00);
  const __m256 c1 = _mm256_fmadd_ps(fy, _mm256_sub_ps(c11, c01), c01);
  return _mm256_fmadd_ps(fz, _mm256_sub_ps(c1, c0), c0);
}
#endif

// The pre-issue-10 hit shading: six scalar interpolations, std::pow. The reference renderer's
// isosurfaces use it, so "within 45 dB of the reference" means "of what the renderer computed before".
void shade_hit_scalar(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
                      const float colour[3], float* a) {
  double q[6][3], h[3], g[3];
  gradient_points(p, dims, spacing, q, h);
  for (int ax = 0; ax < 3; ++ax) {
    const double* q0 = q[2 * ax];
    const double* q1 = q[2 * ax + 1];
    g[ax] = h[ax] > 0 ? (interp_clamped(f, q1[0], q1[1], q1[2]) - interp_clamped(f, q0[0], q0[1], q0[2])) / h[ax] : 0.0;
  }
  shade_from_gradient(g, dir, colour, false, a);
}

// The renderer's hit shading: the same six interpolations (float positions, clamps and lerps of
// interp_clamped(), so the same values) as lanes of one 8-lane gather evaluation, and |n·l|^32 by
// squarings. With eight isosurfaces a ray makes ~3 hits, each of which paid six scalar
// interpolations and a libm pow.
void shade_hit(const FieldAcc& f, const Index3& dims, const Vec3& spacing, const double p[3], const Vec3& dir,
               const float colour[3], float* a) {
  double q[6][3], h[3], g[3];
  gradient_points(p, dims, spacing, q, h);
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    alignas(32) float x[8], y[8], z[8], v[8];
    for (int l = 0; l < 6; ++l) x[l] = float(q[l][0]), y[l] = float(q[l][1]), z[l] = float(q[l][2]);
    x[6] = x[7] = x[0], y[6] = y[7] = y[0], z[6] = z[7] = z[0];  // unused lanes: a valid position
    // interp_clamped(): positions clamped into the data (std::clamp = max then min for numbers),
    // then the cell index clamped to [ilo, ihi].
    auto pos = [&](const float* c, int ax) {
      return _mm256_min_ps(_mm256_max_ps(_mm256_load_ps(c), _mm256_set1_ps(f.plo[ax])), _mm256_set1_ps(f.phi[ax]));
    };
    const __m256 px = pos(x, 0), py = pos(y, 1), pz = pos(z, 2);
    _mm256_store_ps(v, trilinear8(f, px, py, pz));
    for (int ax = 0; ax < 3; ++ax) g[ax] = h[ax] > 0 ? (double(v[2 * ax + 1]) - double(v[2 * ax])) / h[ax] : 0.0;
    shade_from_gradient(g, dir, colour, true, a);
    return;
  }
#endif
  for (int ax = 0; ax < 3; ++ax) {
    const double* q0 = q[2 * ax];
    const double* q1 = q[2 * ax + 1];
    g[ax] = h[ax] > 0 ? (interp_clamped(f, q1[0], q1[1], q1[2]) - interp_clamped(f, q0[0], q0[1], q0[2])) / h[ax] : 0.0;
  }
  shade_from_gradient(g, dir, colour, true, a);
}

// ceil(q) for |q| < 2^62 without a libm call; truncation toward zero already is the ceiling for
// negative q. Runs between macro-cell faces are short, so this is on the per-macro-cell path.
inline std::int64_t ceil_index(double q) {
  const std::int64_t n = std::int64_t(q);
  return n + (double(n) < q);
}

// Sample positions are computed from the sample index alone, p_k = base + k·step in float (one
// multiply-add, no loop-carried chain): every path, run and brick evaluates sample k at the same
// bits, whatever the macro-cell walk did before it.
struct RayPos {
  float bx, by, bz, sx, sy, sz;
};

// Samples are interpolated in blocks of kBlock consecutive samples of one ray: the positions,
// cell indices, eight corner loads (gathers) and the seven lerps of a block run as vector
// instructions, while compositing, which carries the transmittance from sample to sample, stays
// scalar. Every path of the march (single volume task or general) interpolates through this one
// function, so they produce the same bits.
constexpr int kBlock = 8;

// v[l] = the field at sample k0 + l for l < n (1 ≤ n ≤ kBlock); lanes l ≥ n repeat sample
// k0 + n − 1 (valid memory, ignored). `safe`: every sample lies at least one cell inside the data,
// so the scalar fallback may skip the index clamps (the vector version always clamps: it is cheap).
inline void interp_block(const FieldAcc& f, const RayPos& P, std::int64_t k0, int n, bool safe, float* v) {
#ifdef PANOPTES_RENDER_AVX2
  if (f.gather32) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i kk =
        _mm256_min_epi32(_mm256_add_epi32(_mm256_set1_epi32(int(k0)), lane), _mm256_set1_epi32(int(k0) + n - 1));
    const __m256 fk = _mm256_cvtepi32_ps(kk);
    const __m256 x = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sx), _mm256_set1_ps(P.bx));
    const __m256 y = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sy), _mm256_set1_ps(P.by));
    const __m256 z = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sz), _mm256_set1_ps(P.bz));
    _mm256_storeu_ps(v, trilinear8(f, x, y, z));
    return;
  }
#endif
  for (int l = 0; l < kBlock; ++l) {
    const float fk = float(k0 + std::min(l, n - 1));
    const float x = P.bx + fk * P.sx, y = P.by + fk * P.sy, z = P.bz + fk * P.sz;
    v[l] = safe ? interp<false>(f, x, y, z) : interp<true>(f, x, y, z);
  }
}

// The same block from the CornerFields of N fields that share one corner layout (same ilo, ihi, ccx,
// ccxy: fields of one grid and brick), e.g. p and s of a two-field task: the sample positions, cell
// records and the eight trilinear weights are computed once for all N, and per field and sample
// only the 16-byte load of the cell's quantized corners, its widening and one multiply by the
// weights remain (then eight horizontal sums at once). Per field the operations are the same
// whatever N is, so a field's values do not depend on which other fields were read with it (one
// march for K tasks = K marches, bit for bit). Lanes l ≥ n repeat sample k0 + n − 1, as in
// interp_block().
template <int N>
[[gnu::always_inline]] inline void interp_block_corners_n(const FieldAcc* const (&fs)[N], const RayPos& P,
                                                          std::int64_t k0, int n, float* const (&vs)[N]) {
#ifdef PANOPTES_RENDER_AVX2
  const FieldAcc& f = *fs[0];
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i kk =
      _mm256_min_epi32(_mm256_add_epi32(_mm256_set1_epi32(int(k0)), lane), _mm256_set1_epi32(int(k0) + n - 1));
  const __m256 fk = _mm256_cvtepi32_ps(kk);
  const __m256 x = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sx), _mm256_set1_ps(P.bx));
  const __m256 y = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sy), _mm256_set1_ps(P.by));
  const __m256 z = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sz), _mm256_set1_ps(P.bz));
  auto cell = [](__m256 p, int lo, int hi) {
    return _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(p), _mm256_set1_epi32(lo)), _mm256_set1_epi32(hi));
  };
  const __m256i i = cell(x, f.ilo[0], f.ihi[0]), j = cell(y, f.ilo[1], f.ihi[1]), k = cell(z, f.ilo[2], f.ihi[2]);
  alignas(32) float fx[kBlock], fy[kBlock], fz[kBlock];
  alignas(32) std::int32_t id[kBlock];
  _mm256_store_ps(fx, _mm256_sub_ps(x, _mm256_cvtepi32_ps(i)));
  _mm256_store_ps(fy, _mm256_sub_ps(y, _mm256_cvtepi32_ps(j)));
  _mm256_store_ps(fz, _mm256_sub_ps(z, _mm256_cvtepi32_ps(k)));
  _mm256_store_si256(reinterpret_cast<__m256i*>(id),
                     _mm256_add_epi32(_mm256_sub_epi32(i, _mm256_set1_epi32(f.ilo[0])),
                                      _mm256_add_epi32(_mm256_mullo_epi32(_mm256_sub_epi32(j, _mm256_set1_epi32(f.ilo[1])),
                                                                          _mm256_set1_epi32(f.ccx)),
                                                       _mm256_mullo_epi32(_mm256_sub_epi32(k, _mm256_set1_epi32(f.ilo[2])),
                                                                          _mm256_set1_epi32(f.ccxy)))));
  // Weight of corner c = wx·wy·wz with w = 1 − f or f: sign·f + offset per lane.
  const __m256 sx = _mm256_setr_ps(-1, 1, -1, 1, -1, 1, -1, 1), ox = _mm256_setr_ps(1, 0, 1, 0, 1, 0, 1, 0);
  const __m256 sy = _mm256_setr_ps(-1, -1, 1, 1, -1, -1, 1, 1), oy = _mm256_setr_ps(1, 1, 0, 0, 1, 1, 0, 0);
  const __m256 sz = _mm256_setr_ps(-1, -1, -1, -1, 1, 1, 1, 1), oz = _mm256_setr_ps(1, 1, 1, 1, 0, 0, 0, 0);
  __m256 p[N][kBlock];
  for (int l = 0; l < kBlock; ++l) {
    const __m256 wx = _mm256_fmadd_ps(_mm256_broadcast_ss(&fx[l]), sx, ox);
    const __m256 wy = _mm256_fmadd_ps(_mm256_broadcast_ss(&fy[l]), sy, oy);
    const __m256 wz = _mm256_fmadd_ps(_mm256_broadcast_ss(&fz[l]), sz, oz);
    const __m256 w = _mm256_mul_ps(wx, _mm256_mul_ps(wy, wz));
    const std::int64_t o = std::int64_t(f.crec) * id[l];
    for (int s = 0; s < N; ++s) {
      const __m128i q = _mm_loadu_si128(reinterpret_cast<const __m128i*>(fs[s]->corners + o));
      p[s][l] = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_cvtepu16_epi32(q)), w);
    }
  }
  for (int s = 0; s < N; ++s) {
    // Eight horizontal sums at once: lanes of a = samples 0–3 (corners 0–3 | 4–7), of b = samples 4–7.
    const __m256 a = _mm256_hadd_ps(_mm256_hadd_ps(p[s][0], p[s][1]), _mm256_hadd_ps(p[s][2], p[s][3]));
    const __m256 b = _mm256_hadd_ps(_mm256_hadd_ps(p[s][4], p[s][5]), _mm256_hadd_ps(p[s][6], p[s][7]));
    const __m256 t = _mm256_add_ps(_mm256_permute2f128_ps(a, b, 0x20), _mm256_permute2f128_ps(a, b, 0x31));
    _mm256_storeu_ps(vs[s], _mm256_fmadd_ps(t, _mm256_set1_ps(fs[s]->qscale), _mm256_set1_ps(fs[s]->qoff)));
  }
#else
  for (int s = 0; s < N; ++s) {
    const FieldAcc& f = *fs[s];
    float* v = vs[s];
    for (int l = 0; l < kBlock; ++l) {
      const float fk = float(k0 + std::min(l, n - 1));
      const float x = P.bx + fk * P.sx, y = P.by + fk * P.sy, z = P.bz + fk * P.sz;
      const int i = std::min(std::max(int(x), f.ilo[0]), f.ihi[0]);
      const int j = std::min(std::max(int(y), f.ilo[1]), f.ihi[1]);
      const int k = std::min(std::max(int(z), f.ilo[2]), f.ihi[2]);
      const float fx = x - float(i), fy = y - float(j), fz = z - float(k);
      const std::uint16_t* c = f.corners + f.crec * (std::int64_t(i - f.ilo[0]) + std::int64_t(j - f.ilo[1]) * f.ccx +
                                                std::int64_t(k - f.ilo[2]) * f.ccxy);
      const float c00 = c[0] + fx * (c[1] - c[0]), c10 = c[2] + fx * (c[3] - c[2]);
      const float c01 = c[4] + fx * (c[5] - c[4]), c11 = c[6] + fx * (c[7] - c[6]);
      const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
      v[l] = f.qoff + f.qscale * (c0 + fz * (c1 - c0));
    }
  }
#endif
}

// Software prefetch of the corner records of samples k0 … k0 + kBlock − 1 of the N fields (one
// corner layout, as interp_block_corners_n(); the same clamped cell records). The corner copies are
// far larger than L3 and a ray's cells are scattered through them, so without it every block waits
// for memory: in the general (K-task) path, whose blocks composite several tasks and fill the
// out-of-order window (Round 6k), and in the single-task loop too (Round 8: −17 % CPU for one volume
// task on the paper grid at 0.5 voxel; Round 5a's sparser prefetch, every other lane one block ahead,
// had not paid). Prefetches never fault and change no value, so images keep their bits.
constexpr int kPrefetchBlocks = 2;  // distance in blocks: Rounds 6k (K-task path: 1, 2, 3) and 8 (both: 1, 2, 4), docs/rendering.md
template <int N>
[[gnu::always_inline]] inline void prefetch_block_corners(const FieldAcc* const (&fs)[N], const RayPos& P,
                                                          std::int64_t k0) {
#ifdef PANOPTES_RENDER_AVX2
  const FieldAcc& f = *fs[0];
  const __m256 fk = _mm256_cvtepi32_ps(
      _mm256_add_epi32(_mm256_set1_epi32(int(k0)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
  const __m256 x = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sx), _mm256_set1_ps(P.bx));
  const __m256 y = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sy), _mm256_set1_ps(P.by));
  const __m256 z = _mm256_fmadd_ps(fk, _mm256_set1_ps(P.sz), _mm256_set1_ps(P.bz));
  auto cell = [](__m256 p, int lo, int hi) {
    return _mm256_sub_epi32(
        _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(p), _mm256_set1_epi32(lo)), _mm256_set1_epi32(hi)),
        _mm256_set1_epi32(lo));
  };
  alignas(32) std::int32_t id[kBlock];
  _mm256_store_si256(reinterpret_cast<__m256i*>(id),
                     _mm256_add_epi32(cell(x, f.ilo[0], f.ihi[0]),
                                      _mm256_add_epi32(_mm256_mullo_epi32(cell(y, f.ilo[1], f.ihi[1]), _mm256_set1_epi32(f.ccx)),
                                                       _mm256_mullo_epi32(cell(z, f.ilo[2], f.ihi[2]), _mm256_set1_epi32(f.ccxy)))));
  // The two halves of one joint copy (CornerField::joint()): a 32-byte record lies in one cache line.
  const bool joint = N == 2 && (fs[N - 1]->corners == fs[0]->corners + 8 || fs[0]->corners == fs[N - 1]->corners + 8);
  for (int l = 0; l < kBlock; ++l)
    for (int s = 0; s < (joint ? 1 : N); ++s)
      _mm_prefetch(reinterpret_cast<const char*>(fs[s]->corners + std::int64_t(f.crec) * id[l]), _MM_HINT_T0);
#else
  (void)fs, (void)P, (void)k0;
#endif
}

inline void interp_block_corners(const FieldAcc& f, const RayPos& P, std::int64_t k0, int n, float* v) {
  const FieldAcc* const fs[1] = {&f};
  float* const vs[1] = {v};
  interp_block_corners_n<1>(fs, P, k0, n, vs);
}

// Whether two fields' corner copies have the same layout, so interp_block_corners_n() may share
// their geometry.
inline bool same_corner_layout(const FieldAcc& a, const FieldAcc& b) {
  if (!a.corners || !b.corners || a.ccx != b.ccx || a.ccxy != b.ccxy || a.crec != b.crec) return false;
  for (int k = 0; k < 3; ++k)
    if (a.ilo[k] != b.ilo[k] || a.ihi[k] != b.ihi[k]) return false;
  return true;
}

// Volume classification's values: from the corner copy when the field has one.
inline void volume_block(const FieldAcc& f, const RayPos& P, std::int64_t k0, int n, bool safe, float* v) {
  if (f.corners)
    interp_block_corners(f, P, k0, n, v);
  else
    interp_block(f, P, k0, n, safe, v);
}

// LUT bins of a block of values: lut_bin() lane by lane (same operations, so the same bins), as byte
// offsets bin·2^kShift of rows of 2^kShift bytes (the compositing loops then address a row with
// one add: x86 scales indices by at most 8).
template <int kShift>
inline void lut_bin_block(const float* v, float lo, float sc, float last, bool absv, int* bin) {
#ifdef PANOPTES_RENDER_AVX2
  __m256 u = _mm256_loadu_ps(v);
  if (absv) u = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), u);
  u = _mm256_mul_ps(_mm256_sub_ps(u, _mm256_set1_ps(lo)), _mm256_set1_ps(sc));
  u = _mm256_max_ps(u, _mm256_setzero_ps());  // NaN → 0, as in lut_bin()
  u = _mm256_min_ps(u, _mm256_set1_ps(last));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(bin), _mm256_slli_epi32(_mm256_cvttps_epi32(u), kShift));
#else
  for (int l = 0; l < kBlock; ++l) bin[l] = lut_bin(v[l], lo, sc, last, absv) << kShift;
#endif
}

// A single-field volume task's LUT row for the march: premultiplied colour and 1 − α (the factor of
// the transmittance) in 16 bytes, so a sample is one row load, one FMA and one multiply by the row's
// lane 3 (and ten tasks' LUTs take 160 KB of cache instead of 320 KB of LutEntry rows).
std::vector<VolRow> vol_rows(const TransferLut& lut) {
  std::vector<VolRow> m(std::size_t(lut.bins()));
  for (int b = 0; b < lut.bins(); ++b) {
    const LutEntry& e = lut.entry(b);
    m[std::size_t(b)] = {e.pr, e.pg, e.pb, 1.0f - e.alpha};
  }
  return m;
}

// Composites lanes 0 … n−1 of a block (sample k0 + l, LUT bins `bin` as byte offsets of rows) of one single-field volume
// task into the accumulator (colour c0..c2, transmittance tr). Returns the lane where the ray became
// opaque, or −1. Shared by the fast path and the general path, so both give the same bits.
inline int composite_volume1_scalar(const VolRow* lut, const int* bin, int n, std::int64_t k0, std::int64_t k_partial,
                                    float partial, float tr_stop, float& c0, float& c1, float& c2, float& tr) {
  for (int l = 0; l < n; ++l) {
    const VolRow& e = row_at(lut, bin[l]);
    float pr = e.pr, pg = e.pg, pb = e.pb, om = e.om;
    if (k0 + l == k_partial) [[unlikely]] {
      const float al = 1.0f - om;
      const float an = al > 0 ? 1.0f - std::pow(om, partial) : 0.0f;
      const float sf = al > 0 ? an / al : 0.0f;
      pr *= sf, pg *= sf, pb *= sf, om = 1.0f - an;
    }
    c0 = std::fma(tr, pr, c0);
    c1 = std::fma(tr, pg, c1);
    c2 = std::fma(tr, pb, c2);
    tr *= om;
    if (tr <= tr_stop) [[unlikely]]
      return l;
  }
  return -1;
}

inline int composite_volume1(const VolRow* lut, const int* bin, int n, std::int64_t k0, std::int64_t k_partial,
                             float partial, float tr_stop, float& c0, float& c1, float& c2, float& tr) {
#ifdef PANOPTES_RENDER_AVX2
  // The common block (no shortened last sample) with the colour in one 4-lane register: per sample
  // one 16-byte row load, one FMA and the transmittance multiply (lane 3 of c collects junk), and no
  // termination test. The transmittance never increases, so the block's final value tells whether
  // some sample reached tr_stop; only then (once per ray) is the block redone sample by sample from
  // its start. The operations per sample are those of the scalar loop (fused multiply-adds, the
  // same order), so both loops give the same bits.
  if (std::uint64_t(k_partial - k0) >= std::uint64_t(n)) {
    __m128 c = _mm_setr_ps(c0, c1, c2, 0.0f);
    __m128 t = _mm_set1_ps(tr);
    for (int l = 0; l < n; ++l) {
      const __m128 r = _mm_load_ps(&row_at(lut, bin[l]).pr);
      c = _mm_fmadd_ps(t, r, c);
      t = _mm_mul_ps(t, _mm_permute_ps(r, 0xFF));
    }
    if (_mm_cvtss_f32(t) > tr_stop) [[likely]] {
      alignas(16) float cc[4];
      _mm_store_ps(cc, c);
      c0 = cc[0], c1 = cc[1], c2 = cc[2], tr = _mm_cvtss_f32(t);
      return -1;
    }
  }
#endif
  return composite_volume1_scalar(lut, bin, n, k0, k_partial, partial, tr_stop, c0, c1, c2, tr);
}

// The same for a two-field volume task (extinctions add, colours mix by extinction): per sample
// α = 1 − (1 − α1)(1 − α2) and colour (τ1·c1 + τ2·c2)·α/(τ1 + τ2). Rows of MixEntry hold τ·rgb, τ and
// 1 − α, so the numerator and τ are one 4-lane add of the two rows, and no per-sample branch is left:
// τ1 + τ2 = 0 means α1 = α2 = 0, so 1 − om = 0 and the sample adds 0·finite (the divisor is kept
// ≥ FLT_MIN). The division does not depend on the transmittance, so it stays off the loop-carried
// chain (T ← T·om, one multiply).
inline int composite_volume2_scalar(const MixEntry* m1, const MixEntry* m2, const int* bin1, const int* bin2, int n,
                                    std::int64_t k0, std::int64_t k_partial, float partial, float tr_stop, float* a) {
  float c0 = a[0], c1 = a[1], c2 = a[2], tr = a[3];
  int stop = -1;
  for (int l = 0; l < n; ++l) {
    const MixEntry& e1 = row_at(m1, bin1[l]);
    const MixEntry& e2 = row_at(m2, bin2[l]);
    const float tau = e1.tau + e2.tau;
    float om = e1.om * e2.om;  // = exp(−(τ1 + τ2))
    if (k0 + l == k_partial) [[unlikely]] om = std::pow(om, partial);
    const float s = tr * ((1.0f - om) / std::max(tau, std::numeric_limits<float>::min()));
    c0 = std::fma(s, e1.tr + e2.tr, c0);
    c1 = std::fma(s, e1.tg + e2.tg, c1);
    c2 = std::fma(s, e1.tb + e2.tb, c2);
    tr = tr * om;
    if (tr <= tr_stop) [[unlikely]] {
      stop = l;
      break;
    }
  }
  a[0] = c0, a[1] = c1, a[2] = c2, a[3] = tr;
  return stop;
}

inline int composite_volume2(const MixEntry* m1, const MixEntry* m2, const int* bin1, const int* bin2, int n,
                             std::int64_t k0, std::int64_t k_partial, float partial, float tr_stop, float* a) {
#ifdef PANOPTES_RENDER_AVX2
  // As composite_volume1(): the colour accumulated as a 4-lane vector (the same operations as the
  // scalar loop, so the same bits; lane 3 collects s·τ, unused), termination tested once per block.
  if (std::uint64_t(k_partial - k0) >= std::uint64_t(n)) {
    __m128 c = _mm_load_ps(a);  // lane 3 (tr) collects junk, as in composite_group()
    float tr = a[3];
    for (int l = 0; l < n; ++l) {
      const MixEntry& e1 = row_at(m1, bin1[l]);
      const MixEntry& e2 = row_at(m2, bin2[l]);
      const float tau = e1.tau + e2.tau;
      const float om = e1.om * e2.om;
      const float s = tr * ((1.0f - om) / std::max(tau, std::numeric_limits<float>::min()));
      c = _mm_fmadd_ps(_mm_set1_ps(s), _mm_add_ps(_mm_load_ps(&e1.tr), _mm_load_ps(&e2.tr)), c);
      tr = tr * om;
    }
    if (tr > tr_stop) [[likely]] {
      _mm_store_ps(a, c);
      a[3] = tr;
      return -1;
    }
  }
#endif
  return composite_volume2_scalar(m1, m2, bin1, bin2, n, k0, k_partial, partial, tr_stop, a);
}

// One block of G single-field volume tasks (composite_volume1()), sample-outer: each task's
// transmittance and colour form a latency chain of a multiply and an FMA per sample; interleaved,
// the G chains run side by side. Per task the operations and their order are those of
// composite_volume1(), so the same bits. The block is composited in registers; a task whose
// transmittance reached tr_stop (once per ray), or a block holding the shortened last sample, is
// redone by the scalar loop from its accumulator a[g] = {c0, c1, c2, tr}, written only on success.
// Fills stop[g] as composite_volume1() returns it.
template <int G>
inline void composite_group(const VolRow* const* luts, const int (*bins)[kBlock], float* const* a, int* stop, int n,
                            std::int64_t k0, std::int64_t k_partial, float partial, float tr_stop) {
#ifdef PANOPTES_RENDER_AVX2
  if (std::uint64_t(k_partial - k0) >= std::uint64_t(n)) {
    __m128 c[G], t[G];  // lane 3 of c starts at tr and collects junk
    for (int g = 0; g < G; ++g) c[g] = _mm_load_ps(a[g]), t[g] = _mm_broadcast_ss(a[g] + 3);
    for (int l = 0; l < n; ++l)
      for (int g = 0; g < G; ++g) {
        const __m128 r = _mm_load_ps(&row_at(luts[g], bins[g][l]).pr);
        c[g] = _mm_fmadd_ps(t[g], r, c[g]);
        t[g] = _mm_mul_ps(t[g], _mm_permute_ps(r, 0xFF));
      }
    for (int g = 0; g < G; ++g) {
      const float tr = _mm_cvtss_f32(t[g]);
      if (tr > tr_stop) [[likely]] {
        _mm_store_ps(a[g], c[g]);
        a[g][3] = tr;
        stop[g] = -1;
      } else {
        stop[g] = composite_volume1_scalar(luts[g], bins[g], n, k0, k_partial, partial, tr_stop, a[g][0], a[g][1],
                                           a[g][2], a[g][3]);
      }
    }
    return;
  }
#endif
  for (int g = 0; g < G; ++g)
    stop[g] = composite_volume1_scalar(luts[g], bins[g], n, k0, k_partial, partial, tr_stop, a[g][0], a[g][1],
                                       a[g][2], a[g][3]);
}

// The single-volume-task loop over samples kb … kend with field, LUT and accumulator in registers.
// Returns one past the last sample marched (< kend + 1 when the ray became opaque).
std::int64_t march_volume1(const FieldAcc& f, const TaskRt& T, float* a, std::int64_t kb, std::int64_t kend,
                           const RayPos& P, bool safe, std::int64_t k_partial, float partial, float tr_stop,
                           bool& opaque) {
  // Transmittance form: the loop-carried chain is one multiply (T ← T·(1 − α)) instead of
  // α ← α + (1 − α)·α_s, which shortens the per-sample latency.
  float a0 = a[0], a1 = a[1], a2 = a[2], tr = a[3];
  alignas(32) float v[kBlock];
  alignas(32) int bin[kBlock];
  for (std::int64_t k0 = kb; k0 <= kend; k0 += kBlock) {
    const int n = int(std::min<std::int64_t>(kBlock, kend - k0 + 1));
    if (f.corners && k0 + kPrefetchBlocks * kBlock <= kend) {
      const FieldAcc* const fs[1] = {&f};
      prefetch_block_corners<1>(fs, P, k0 + kPrefetchBlocks * kBlock);
    }
    volume_block(f, P, k0, n, safe, v);
    lut_bin_block<kRowShift>(v, T.lo1, T.sc1, T.last1, T.abs1, bin);
    const int stop = composite_volume1(T.row1, bin, n, k0, k_partial, partial, tr_stop, a0, a1, a2, tr);
    if (stop >= 0) [[unlikely]] {
      opaque = true;
      a[0] = a0, a[1] = a1, a[2] = a2, a[3] = tr;
      return k0 + stop + 1;
    }
  }
  a[0] = a0, a[1] = a1, a[2] = a2, a[3] = tr;
  return kend + 1;
}

// The paper's three tasks (p, s and p+s: single-field volume tasks 1 and 2 on fields a and b, and
// the two-field task 3 on both), or those of them in the bits of M that are still live (at least
// two, or task 3 alone), in one loop with their accumulators in registers: per task the operations
// are those of composite_group() and composite_volume2(), so the same bits. Returns one past the
// last sample consumed; `done` receives the tasks (bits 0–2) that became opaque in the last block;
// a block holding k_partial is left to the caller.
template <unsigned M>
std::int64_t march_trio(const FieldAcc& fa, const FieldAcc& fb, const TaskRt& T1, const TaskRt& T2, const TaskRt& T3,
                        float* a1, float* a2, float* a3, std::int64_t kb, std::int64_t kend, const RayPos& P,
                        std::int64_t k_partial, float partial, float tr_stop, unsigned& done) {
  done = 0;
#ifdef PANOPTES_RENDER_AVX2
  constexpr bool t1 = M & 1, t2 = M & 2, t3 = M & 4;
  static_assert(t3 || (t1 && t2), "a single single-field task takes march_volume1()");
  const FieldAcc* const fs[2] = {&fa, &fb};  // every such subset reads both fields
  alignas(32) float vp[kBlock], vs[kBlock];
  float* const vv[2] = {vp, vs};
  alignas(32) int b1[kBlock], b2[kBlock], m1[kBlock], m2[kBlock];
  __m128 c1{}, w1{}, c2{}, w2{}, c3{};
  float tr3 = 0;
  if constexpr (t1) c1 = _mm_load_ps(a1), w1 = _mm_broadcast_ss(a1 + 3);
  if constexpr (t2) c2 = _mm_load_ps(a2), w2 = _mm_broadcast_ss(a2 + 3);
  if constexpr (t3) c3 = _mm_load_ps(a3), tr3 = a3[3];
  std::int64_t k0 = kb;
  for (; k0 <= kend; k0 += kBlock) {
    const int n = int(std::min<std::int64_t>(kBlock, kend - k0 + 1));
    if (std::uint64_t(k_partial - k0) < std::uint64_t(n)) break;
    if (k0 + kPrefetchBlocks * kBlock <= kend) prefetch_block_corners<2>(fs, P, k0 + kPrefetchBlocks * kBlock);
    interp_block_corners_n<2>(fs, P, k0, n, vv);
    if constexpr (t1) lut_bin_block<kRowShift>(vp, T1.lo1, T1.sc1, T1.last1, T1.abs1, b1);
    if constexpr (t2) lut_bin_block<kRowShift>(vs, T2.lo1, T2.sc1, T2.last1, T2.abs1, b2);
    if constexpr (t3) {
      lut_bin_block<kMixShift>(vp, T3.lo1, T3.sc1, T3.last1, T3.abs1, m1);
      lut_bin_block<kMixShift>(vs, T3.lo2, T3.sc2, T3.last2, T3.abs2, m2);
    }
    const __m128 c1s = c1, w1s = w1, c2s = c2, w2s = w2, c3s = c3;
    const float tr3s = tr3;
    for (int l = 0; l < n; ++l) {
      if constexpr (t1) {
        const __m128 r1 = _mm_load_ps(&row_at(T1.row1, b1[l]).pr);
        c1 = _mm_fmadd_ps(w1, r1, c1);
        w1 = _mm_mul_ps(w1, _mm_permute_ps(r1, 0xFF));
      }
      if constexpr (t2) {
        const __m128 r2 = _mm_load_ps(&row_at(T2.row1, b2[l]).pr);
        c2 = _mm_fmadd_ps(w2, r2, c2);
        w2 = _mm_mul_ps(w2, _mm_permute_ps(r2, 0xFF));
      }
      if constexpr (t3) {
        const MixEntry& e1 = row_at(T3.mix1, m1[l]);
        const MixEntry& e2 = row_at(T3.mix2, m2[l]);
        const float tau = e1.tau + e2.tau;
        const float om = e1.om * e2.om;
        const float s = tr3 * ((1.0f - om) / std::max(tau, std::numeric_limits<float>::min()));
        c3 = _mm_fmadd_ps(_mm_set1_ps(s), _mm_add_ps(_mm_load_ps(&e1.tr), _mm_load_ps(&e2.tr)), c3);
        tr3 = tr3 * om;
      }
    }
    const bool o1 = t1 && !(_mm_cvtss_f32(w1) > tr_stop), o2 = t2 && !(_mm_cvtss_f32(w2) > tr_stop),
               o3 = t3 && !(tr3 > tr_stop);
    if (o1 || o2 || o3) [[unlikely]] {
      // As composite_group() / composite_volume2(): a task that reached tr_stop is redone sample by
      // sample from the block's start; the others keep the block's result.
      auto keep = [](float* a, __m128 c, float tr) { _mm_store_ps(a, c), a[3] = tr; };
      int used = 0;  // as the general path counts marched samples: n unless every task stopped
      auto finish1 = [&](bool opaque, unsigned bit, const TaskRt& T, const int* b, float* a, __m128 c, __m128 w,
                         __m128 cs, __m128 ws) {
        if (!opaque) return keep(a, c, _mm_cvtss_f32(w));
        keep(a, cs, _mm_cvtss_f32(ws));
        used = std::max(used, 1 + composite_volume1_scalar(T.row1, b, n, k0, k_partial, partial, tr_stop, a[0], a[1],
                                                           a[2], a[3]));
        done |= bit;
      };
      if constexpr (t1) finish1(o1, 1, T1, b1, a1, c1, w1, c1s, w1s);
      if constexpr (t2) finish1(o2, 2, T2, b2, a2, c2, w2, c2s, w2s);
      if constexpr (t3) {
        if (o3) {
          keep(a3, c3s, tr3s);
          used = std::max(used, 1 + composite_volume2_scalar(T3.mix1, T3.mix2, m1, m2, n, k0, k_partial, partial,
                                                             tr_stop, a3));
          done |= 4;
        } else {
          keep(a3, c3, tr3);
        }
      }
      return k0 + (done == M ? used : n);
    }
  }
  if constexpr (t1) _mm_store_ps(a1, c1), a1[3] = _mm_cvtss_f32(w1);
  if constexpr (t2) _mm_store_ps(a2, c2), a2[3] = _mm_cvtss_f32(w2);
  if constexpr (t3) _mm_store_ps(a3, c3), a3[3] = tr3;
  return std::min(k0, kend + 1);  // the last block may have held fewer than kBlock samples
#else
  (void)fa, (void)fb, (void)T1, (void)T2, (void)T3, (void)a1, (void)a2, (void)a3, (void)kend, (void)P, (void)k_partial,
      (void)partial, (void)tr_stop;
  return kb;
#endif
}

constexpr int kMaxSweep = 12;  // march_volumes(): up to this many tasks on one field (more take the general path)

// G ≥ 2 single-field volume tasks on ONE field (a sweep of transfer functions or windows), all of
// them live: blocks of samples kb … kend run without the general path's per-block bookkeeping (which
// tasks read which fields, their kinds, their slots), the per-task constants loaded once. Per task
// the operations are those of composite_group(), so the same bits. Returns one past the last sample
// marched and, in `done`, the bits (of 0 … G−1) of the tasks that became opaque — at the first block
// where any did, so the caller can drop them and go on with fewer.
template <int G>
std::int64_t march_volumes(const FieldAcc& f, const TaskRt* const* T, float* const* as, std::int64_t kb,
                           std::int64_t kend, const RayPos& P, bool safe, std::int64_t k_partial, float partial,
                           float tr_stop, unsigned& done) {
  done = 0;
  const VolRow* luts[G];
  float lo[G], sc[G], last[G];
  bool absv[G];
  for (int g = 0; g < G; ++g) luts[g] = T[g]->row1, lo[g] = T[g]->lo1, sc[g] = T[g]->sc1, last[g] = T[g]->last1,
                              absv[g] = T[g]->abs1;
  alignas(32) float v[kBlock];
  alignas(32) int bins[G][kBlock];
  int stops[G];
  std::int64_t k0 = kb;
  for (; k0 <= kend; k0 += kBlock) {
    const int n = int(std::min<std::int64_t>(kBlock, kend - k0 + 1));
    if (f.corners && k0 + kPrefetchBlocks * kBlock <= kend) {
      const FieldAcc* const fs[1] = {&f};
      prefetch_block_corners<1>(fs, P, k0 + kPrefetchBlocks * kBlock);
    }
    volume_block(f, P, k0, n, safe, v);
    for (int g = 0; g < G; ++g) lut_bin_block<kRowShift>(v, lo[g], sc[g], last[g], absv[g], bins[g]);
    // In groups of four, as the general path composites them (the chains of a group interleaved).
    [&]<int... Q>(std::integer_sequence<int, Q...>) {
      (composite_group<std::min(4, G - 4 * Q)>(luts + 4 * Q, bins + 4 * Q, as + 4 * Q, stops + 4 * Q, n, k0, k_partial,
                                               partial, tr_stop),
       ...);
    }(std::make_integer_sequence<int, (G + 3) / 4>{});
    int used = 0;
    for (int g = 0; g < G; ++g)
      if (stops[g] >= 0) done |= 1u << g, used = std::max(used, stops[g] + 1);
    if (done) [[unlikely]]
      return k0 + (done == (1u << G) - 1 ? used : n);
  }
  return std::min(k0, kend + 1);  // the last block may have held fewer than kBlock samples
}

// Marches one ray through the brick for the march tasks in `tasks`; fills acc[i] (premultiplied) per task.
// Returns the effective and marched sample counts through the references.
void march_ray(const Shared& S, const double O[3], const double D[3], const Vec3& dir, double t0, double tg1,
               double tb0, double tb1, std::uint64_t tasks, float (*acc)[4], std::uint64_t& effective,
               std::uint64_t& marched) {
  const std::uint64_t mm = S.march_mask & tasks;  // the march tasks of this ray
  const double dt = S.dt;
  const Brick& B = S.brick;
  const std::int64_t kg_last = std::int64_t(std::ceil((tg1 - t0) / dt)) - 1;
  std::int64_t ks = std::max<std::int64_t>(0, std::int64_t(std::ceil((tb0 - t0) / dt)) - 1);
  std::int64_t ke = std::min(kg_last, std::int64_t(std::floor((tb1 - t0) / dt)) + 1);
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
  if (ks > ke) return;
  effective += std::uint64_t(ke - ks + 1);
  // During the march acc[i][3] holds the TRANSMITTANCE T = 1 − α: the loop-carried chain per
  // sample is then one multiply, T ← T·(1 − α_s), and colour accumulates as C ← C + T·c_s·α_s.
  for (std::uint64_t m = mm; m; m &= m - 1) acc[std::countr_zero(m)][3] = 1.0f;
  FieldAcc fa[8];  // local copies: no aliasing with the accumulators, so no reloads per sample
  for (std::size_t s = 0; s < S.acc.size(); ++s) fa[s] = S.acc[s];
  // The last sample of the ray in the whole domain stands for a shorter segment.
  std::int64_t k_partial = -1;
  float partial = 1;
  if (ke == kg_last) {
    const double f = (tg1 - (t0 + double(kg_last) * dt)) / dt;
    if (f < 1 - 1e-6) {
      k_partial = kg_last;
      partial = float(std::max(0.0, f));
    }
  }

  std::uint64_t live = mm;
  // vb[s][0] holds slot s's value at the sample before the current block, vb[s][1 + l] the block's
  // values; prev_valid: slots whose vb[s][0] is that previous sample (isosurface crossings need it).
  alignas(32) float vb[8][2 * kBlock];
  alignas(32) float vq[8][kBlock];
  std::uint32_t prev_valid = 0, vq_from_vb = 0;
  const RayPos P{float(O[0] + t0 * D[0]), float(O[1] + t0 * D[1]), float(O[2] + t0 * D[2]),
                 float(dt * D[0]),        float(dt * D[1]),        float(dt * D[2])};
  const float tr_stop = 1.0f - S.termination;

  auto single_volume = [&](std::uint64_t m) {
    return m && !(m & (m - 1)) && S.rt[std::size_t(std::countr_zero(m))].kind == RtKind::volume1;
  };
  // Marches samples kb … kend, in consecutive macro-cells whose live tasks are all `mask`; `safe`:
  // the cells lie inside the data with a one-cell margin, so interpolation needs no clamps.
  auto run = [&](std::int64_t kb, std::int64_t kend, std::uint64_t mask, bool safe) {
    for (std::int64_t k0 = kb; k0 <= kend; k0 += kBlock) {
      const std::uint64_t lm = mask & live;
      if (!lm) break;
      if (single_volume(lm)) {
        // Fast path: one volume task left (from the start, or the others terminated).
        const int i = std::countr_zero(lm);
        const TaskRt& T = S.rt[std::size_t(i)];
        bool opaque = false;
        const std::int64_t kk =
            march_volume1(fa[T.s1], T, acc[i], k0, kend, P, safe, k_partial, partial, tr_stop, opaque);
        if (opaque) live &= ~(std::uint64_t(1) << i);
        marched += std::uint64_t(kk - k0);
        prev_valid = 0;  // values were not kept (no isosurface task is live here)
        return;
      }
      if (S.trio_mask && !(lm & ~S.trio_mask)) {
        // The paper's mix, or what is left of it (a single volume task took the fast path above).
        unsigned sub = 0, done = 0;
        for (int q = 0; q < 3; ++q) sub |= unsigned(lm >> S.trio[q] & 1) << q;
        const TaskRt &T1 = S.rt[std::size_t(S.trio[0])], &T2 = S.rt[std::size_t(S.trio[1])],
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
        if (kk > k0) {
          k0 = kk - kBlock;  // the loop's increment moves to kk
          continue;
        }
      }
      if (!(lm & ~S.volume1_mask) &&
          !(lm & ~S.volume1_on_slot[std::size_t(S.rt[std::size_t(std::countr_zero(lm))].s1)])) {
        // Single-field volume tasks on one field only (two or more: one took the fast path above).
        const int G = std::popcount(lm);
        if (G <= kMaxSweep) {
          const TaskRt* T[kMaxSweep];
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
          k0 = kk - kBlock;  // the loop's increment moves to kk
          continue;
        }
      }
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
        const TaskRt& T = S.rt[std::size_t(std::countr_zero(m))];
        (T.kind == RtKind::iso ? smask : vmask) |= T.slots;
      }
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
        interp_block(fa[s], P, k0, n, safe, &vb[s][1]);
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
          const TaskRt& T = S.rt[std::size_t(i)];
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
        const TaskRt& T = S.rt[std::size_t(i)];
        float* a = acc[i];
        int stop = -1;
        switch (T.kind) {
          case RtKind::volume1:  // composited above, in groups
            break;
          case RtKind::volume2: {
            alignas(32) int bin1[kBlock], bin2[kBlock];
            lut_bin_block<kMixShift>(vq[T.s1], T.lo1, T.sc1, T.last1, T.abs1, bin1);
            lut_bin_block<kMixShift>(vq[T.s2], T.lo2, T.sc2, T.last2, T.abs2, bin2);
            stop = composite_volume2(T.mix1, T.mix2, bin1, bin2, n, k0, k_partial, partial, tr_stop, a);
            break;
          }
          case RtKind::iso: {
            const float* v = vb[T.s1];
            const int l0 = (prev_valid >> T.s1 & 1) ? 0 : 1;
            // Lanes whose segment (sample l − 1 … l) changes sign, found for the whole block at once.
            unsigned cross = 0;
#ifdef PANOPTES_RENDER_AVX2
            {
              const __m256 iso = _mm256_set1_ps(T.iso), zero = _mm256_setzero_ps();
              const __m256 sp = _mm256_cmp_ps(_mm256_sub_ps(_mm256_loadu_ps(v), iso), zero, _CMP_LT_OQ);
              const __m256 sn = _mm256_cmp_ps(_mm256_sub_ps(_mm256_loadu_ps(v + 1), iso), zero, _CMP_LT_OQ);
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
          case RtKind::slice:
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
  };

  if (S.direct) {
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
    if (clear) {
      // One run over the whole ray: the samples and their order are those of the merged walk, so
      // images are the same bits; `safe` = false only means clamped indices (same bits, see interp()).
      run(ks, ke, mm, false);
      for (std::uint64_t m = mm; m; m &= m - 1) {
        float* a = acc[std::countr_zero(m)];
        a[3] = 1.0f - a[3];
      }
      return;
    }
  }

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
  for (std::uint64_t m = mm; m; m &= m - 1) {
    float* a = acc[std::countr_zero(m)];
    a[3] = 1.0f - a[3];  // transmittance back to opacity
  }
}

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

  Shared S;
  S.cam = &cam;
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

  std::vector<TransferLut> luts(2 * tasks.size());
  std::vector<std::vector<MixEntry>> mixes(2 * tasks.size());
  std::vector<std::vector<VolRow>> rows(tasks.size());
  S.rt.resize(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const TaskSpec& t = tasks[i];
    TaskRt& r = S.rt[i];
    const std::uint64_t bit = std::uint64_t(1) << i;
    auto bake = [&](const TransferFunction& tf, const ValueWindow& w, double ref, int which) -> TransferLut& {
      luts[2 * i + std::size_t(which)] = TransferLut(tf, w.resolve(ref), opt.sample_distance);
      return luts[2 * i + std::size_t(which)];
    };
    switch (t.kind) {
      case TaskKind::volume: {
        r.kind = t.field2 >= 0 ? RtKind::volume2 : RtKind::volume1;
        r.s1 = slot(t.field);
        r.slots = 1u << r.s1;
        const TransferLut& l1 = bake(t.tf, t.window, t.reference, 0);
        r.lut1 = &l1.entry(0);
        r.lo1 = l1.lo(), r.sc1 = l1.scale(), r.last1 = float(l1.bins() - 1), r.abs1 = l1.absolute_value();
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
        r.kind = RtKind::iso;
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
        r.kind = RtKind::slice;
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
    }
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
    if ((S.march_mask >> i & 1) && S.rt[i].kind == RtKind::volume1)
      S.volume1_on_slot[std::size_t(S.rt[i].s1)] |= std::uint64_t(1) << i;
  // The paper's mix (march_trio()): a two-field task on two corner copies of one layout, with a
  // single-field task on each of its fields.
  for (std::size_t i3 = 0; i3 < S.rt.size() && !S.trio_mask; ++i3) {
    const TaskRt& r3 = S.rt[i3];
    if (!(S.march_mask >> i3 & 1) || r3.kind != RtKind::volume2 || r3.s1 == r3.s2) continue;
    if (!(S.corner_slots >> r3.s1 & 1) || !(S.corner_slots >> r3.s2 & 1) ||
        !(S.corner_mates[std::size_t(r3.s1)] >> r3.s2 & 1))
      continue;
    int i1 = -1, i2 = -1;
    for (std::size_t i = 0; i < S.rt.size(); ++i) {
      if (!(S.march_mask >> i & 1) || S.rt[i].kind != RtKind::volume1) continue;
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
      const TaskRt& r = S.rt[i];
      const std::uint64_t bit = std::uint64_t(1) << i;
      if (!(S.march_mask & bit)) continue;
      if (!opt.skip_empty) {
        bits |= bit;
        continue;
      }
      const MacroCells& c1 = *S.cells[std::size_t(r.s1)];
      if (r.kind == RtKind::iso) {
        if (c1.min(m) <= r.iso && r.iso <= c1.max(m)) bits |= bit;
      } else {
        // Quantized values may stray half a step outside the cell's float range.
        const float e1 = S.acc[std::size_t(r.s1)].qscale;
        bool vis = luts[2 * i].visible(c1.min(m) - e1, c1.max(m) + e1);
        if (!vis && r.kind == RtKind::volume2) {
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
  // Every pixel of the rect is written below (a miss as transparent, +∞): no clearing first.
  for (PartialImage& o : out) o.resize(W, H, rect);
  rect = out.empty() ? PixelRect{} : out[0].rect;
  if (tasks.empty()) return stats;

  const int tile = opt.tile;
  // Tiles lie on multiples of the tile edge in image coordinates (clipped to the rect), so the
  // bricks of a decomposition cut their footprints into the same tiles where they overlap: with
  // adaptive sampling their lattices, and so most refinement decisions, then coincide.
  const int tx_first = rect.x0 / tile, ty_first = rect.y0 / tile;
  const int ntx = rect.empty() ? 0 : (rect.x1 - 1) / tile - tx_first + 1;
  const int nty = rect.empty() ? 0 : (rect.y1 - 1) / tile - ty_first + 1;
  const int K = int(tasks.size());
  const double glo[3] = {0, 0, 0};
  const double ghi[3] = {double(S.grid.dims[0] - 1), double(S.grid.dims[1] - 1), double(S.grid.dims[2] - 1)};
  const double blo[3] = {double(S.brick.lo[0]), double(S.brick.lo[1]), double(S.brick.lo[2])};
  const double bhi[3] = {double(S.brick.hi[0]), double(S.brick.hi[1]), double(S.brick.hi[2])};
  if (opt.adaptive && opt.adaptive_stride < 2)
    throw Error("render: adaptive stride " + std::to_string(opt.adaptive_stride) + "; expected >= 2");
  if (opt.adaptive && !(opt.adaptive_tolerance >= 0))
    throw Error("render: adaptive tolerance " + std::to_string(opt.adaptive_tolerance) + "; expected >= 0");
  std::uint64_t n_rays = 0, n_eff = 0, n_marched = 0, n_interpolated = 0;
  const std::uint64_t all_tasks = K == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << K) - 1;
  // Adaptive sampling: isosurfaces and slices are refined wherever any task is (their edges are thin).
  std::uint64_t edge_tasks = 0;
  for (int i = 0; i < K; ++i)
    if (S.rt[std::size_t(i)].kind == RtKind::iso || S.rt[std::size_t(i)].kind == RtKind::slice)
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
    if (!slab(r.O, r.D, glo, ghi, tg0, r.tg1, ag)) return false;
    r.t0 = std::max(tg0, 0.0);
    if (r.tg1 <= r.t0) return false;
    if (whole_domain) {  // the brick's slab test would repeat the domain's, bit for bit
      r.tb0 = tg0, r.tb1 = r.tg1, ab = ag;
    } else if (!slab(r.O, r.D, blo, bhi, r.tb0, r.tb1, ab)) {
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
  auto shade = [&](int x, int y, const PixelRay& r, std::uint64_t tasks, float (*acc)[4], std::uint64_t& eff,
                   std::uint64_t& marched) {
    for (int i = 0; i < K; ++i) acc[i][0] = acc[i][1] = acc[i][2] = acc[i][3] = 0;
    if (S.march_mask & tasks) march_ray(S, r.O, r.D, r.dir, r.t0, r.tg1, r.tb0, r.tb1, tasks, acc, eff, marched);
    for (int i : S.slices) {
      if (!(tasks >> i & 1)) continue;
      const TaskRt& rt = S.rt[std::size_t(i)];
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
      const float v = interp_clamped(S.acc[std::size_t(rt.s1)], p[0], p[1], p[2]);
      const LutEntry& e = rt.lut1[lut_bin(v, rt.lo1, rt.sc1, rt.last1, rt.abs1)];
      acc[i][0] = e.r * rt.opacity, acc[i][1] = e.g * rt.opacity, acc[i][2] = e.b * rt.opacity, acc[i][3] = rt.opacity;
    }
    for (int i = 0; i < K; ++i) {
      PartialImage& o = out[std::size_t(i)];
      if (tasks >> i & 1) {
        float* dst = o.rgba_at(x, y);
        dst[0] = acc[i][0], dst[1] = acc[i][1], dst[2] = acc[i][2], dst[3] = acc[i][3];
      }
      o.depth[std::size_t(y - o.rect.y0) * o.rect.width() + (x - o.rect.x0)] = r.depth;
    }
  };

  auto clear_pixel = [&](int x, int y) {  // a miss
    for (int i = 0; i < K; ++i) {
      PartialImage& o = out[std::size_t(i)];
      float* dst = o.rgba_at(x, y);
      dst[0] = dst[1] = dst[2] = dst[3] = 0;
      o.depth[std::size_t(y - o.rect.y0) * o.rect.width() + (x - o.rect.x0)] = PartialImage::kNoDepth;
    }
  };

#pragma omp parallel reduction(+ : n_rays, n_eff, n_marched, n_interpolated)
  {
    alignas(64) float acc[kMaxTasksPerMarch][4];
    AdaptiveTile refiner(opt.adaptive_stride, opt.adaptive_tolerance);
#pragma omp for schedule(dynamic, 1)
    for (int ti = 0; ti < ntx * nty; ++ti) {
      const int tx0 = std::max(rect.x0, (tx_first + ti % ntx) * tile), ty0 = std::max(rect.y0, (ty_first + ti / ntx) * tile);
      const int tx1 = std::min((tx_first + ti % ntx + 1) * tile, rect.x1), ty1 = std::min((ty_first + ti / ntx + 1) * tile, rect.y1);
      PixelRay r;
      if (!opt.adaptive) {
        for (int y = ty0; y < ty1; ++y)
          for (int x = tx0; x < tx1; ++x) {
            if (!locate(x, y, r)) {
              clear_pixel(x, y);
              continue;
            }
            ++n_rays;
            shade(x, y, r, all_tasks, acc, n_eff, n_marched);
          }
        continue;
      }
      auto march = [&](int x, int y, std::uint64_t tasks) -> std::uint8_t {
        if (locate(x, y, r)) {
          ++n_rays;
          shade(x, y, r, tasks, acc, n_eff, n_marched);
          return r.face;
        }
        clear_pixel(x, y);
        return std::uint8_t(0);
      };
      auto depth_of = [&](int x, int y, std::uint8_t face) {
        if (face) return face_depth(x, y, face);
        return locate(x, y, r) ? r.depth : PartialImage::kNoDepth;
      };
      const std::uint64_t before = refiner.interpolated();
      refiner.run(PixelRect{tx0, ty0, tx1, ty1}, out, march, depth_of, edge_tasks, silhouette.empty() ? nullptr : &silhouette);
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

void shade_isosurface_hit(const FieldView& v, const double p[3], const Vec3& dir, Rgb colour, bool renderer,
                          float rgba[4]) {
  v.validate();
  const FieldAcc f = make_acc(v);
  const float c[3] = {colour.r, colour.g, colour.b};
  if (renderer)
    shade_hit(f, v.grid.dims, v.grid.spacing, p, dir, c, rgba);
  else
    shade_hit_scalar(f, v.grid.dims, v.grid.spacing, p, dir, c, rgba);
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
  std::vector<PreparedField> out(static_cast<std::size_t>(n));
  for (int f = 0; f < n; ++f) {
    const FieldView& v = views[std::size_t(f)];
    const int p = partner[std::size_t(f)];
    if (p >= 0 && p < f) continue;  // built with its partner
    if (p >= 0) {
      auto [cf, cp] = CornerField::joint(v, views[std::size_t(p)]);
      out[std::size_t(f)] = PreparedField(v, std::move(cf), macro_cell_size);
      out[std::size_t(p)] = PreparedField(views[std::size_t(p)], std::move(cp), macro_cell_size);
    } else {
      out[std::size_t(f)] =
          PreparedField(v, macro_cell_size, volume[std::size_t(f)] ? FieldCopy::corners16 : FieldCopy::none);
    }
  }
  return out;
}

}  // namespace panoptes::render
