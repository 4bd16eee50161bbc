#include "render/corner_field.hpp"

#include <string>

#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <sys/mman.h>

#include <cstdlib>
#include <iterator>
#include <mutex>
#include <unordered_map>

namespace panoptes::render {

namespace {

constexpr std::size_t kHuge = std::size_t(2) << 20;

// The large blocks handed out (their rounded sizes) and the freed ones kept for reuse, oldest first.
struct HugeBlocks {
  std::mutex mutex;
  std::unordered_map<void*, std::size_t> live;
  std::vector<std::pair<void*, std::size_t>> idle;
};
HugeBlocks& huge_blocks() {
  static HugeBlocks* blocks = new HugeBlocks;  // never destroyed: blocks may be freed from static destructors
  return *blocks;
}

}  // namespace

void* allocate_huge(std::size_t bytes) {
  if (bytes < kHuge) {
    void* p = std::malloc(bytes == 0 ? 1 : bytes);
    if (!p) throw std::bad_alloc();
    return p;
  }
  const std::size_t n = (bytes + kHuge - 1) / kHuge * kHuge;
  HugeBlocks& b = huge_blocks();
  {
    const std::lock_guard lock(b.mutex);
    for (auto it = b.idle.rbegin(); it != b.idle.rend(); ++it)
      if (it->second == n) {
        void* p = it->first;
        b.idle.erase(std::next(it).base());
        b.live.emplace(p, n);
        return p;
      }
  }
  void* p = std::aligned_alloc(kHuge, n);
  if (!p) throw std::bad_alloc();
  ::madvise(p, n, MADV_HUGEPAGE);  // advice only: without huge pages the copy works as before
  const std::lock_guard lock(b.mutex);
  b.live.emplace(p, n);
  return p;
}

void deallocate_huge(void* p) noexcept {
  if (!p) return;
  HugeBlocks& b = huge_blocks();
  void* dropped = nullptr;
  {
    const std::lock_guard lock(b.mutex);
    const auto it = b.live.find(p);
    if (it == b.live.end()) {
      dropped = p;  // a small block from malloc
    } else {
      b.idle.emplace_back(p, it->second);
      b.live.erase(it);
      if (b.idle.size() > kIdleHugeBlocks) {
        dropped = b.idle.front().first;
        b.idle.erase(b.idle.begin());
      }
    }
  }
  std::free(dropped);
}

void release_idle_huge_blocks() noexcept {
  HugeBlocks& b = huge_blocks();
  std::vector<std::pair<void*, std::size_t>> idle;
  {
    const std::lock_guard lock(b.mutex);
    idle.swap(b.idle);
  }
  for (const auto& [p, n] : idle) std::free(p);
}

std::size_t idle_huge_bytes() noexcept {
  HugeBlocks& b = huge_blocks();
  const std::lock_guard lock(b.mutex);
  std::size_t sum = 0;
  for (const auto& [p, n] : b.idle) sum += n;
  return sum;
}

bool CornerField::shape(const FieldView& f) {
  f.validate();
  const PointRange& pr = f.points;
  std::int64_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    lo_[a] = pr.lo[a];
    counts_[a] = std::max(1, pr.hi[a] - pr.lo[a] - 1);
    cells *= counts_[a];
  }
  if (cells > std::numeric_limits<std::int32_t>::max()) {
    counts_ = {0, 0, 0};
    return false;
  }
  return true;
}

CornerField::CornerField(const FieldView& f, QuantizationRange keep) {
  if (!shape(f)) return;
  const Points pq = quantize(f, keep);
  const std::uint16_t* const list[1] = {pq.get()};
  q_ = write_records(list, 1, f, counts_);
  data_ = q_.get();
}

std::pair<CornerField, CornerField> CornerField::joint(const FieldView& a, const FieldView& b, QuantizationRange keep_a,
                                                       QuantizationRange keep_b) {
  a.validate();
  b.validate();
  if (a.points.lo != b.points.lo || a.points.hi != b.points.hi)
    throw Error("CornerField::joint: the two views cover different point ranges ([" + std::to_string(a.points.lo[0]) +
                ", " + std::to_string(a.points.hi[0]) + ") vs [" + std::to_string(b.points.lo[0]) + ", " +
                std::to_string(b.points.hi[0]) + ") along x, or along y or z); a joint copy needs the same range");
  std::pair<CornerField, CornerField> r;
  if (!r.first.shape(a) || !r.second.shape(b)) return {};
  const Points pa = r.first.quantize(a, keep_a), pb = r.second.quantize(b, keep_b);
  const std::uint16_t* const list[2] = {pa.get(), pb.get()};
  r.first.q_ = r.second.q_ = write_records(list, 2, a, r.first.counts_);
  r.first.record_ = r.second.record_ = 16;
  r.first.data_ = r.first.q_.get();
  r.second.data_ = r.first.q_.get() + 8;
  return r;
}

CornerField::Points CornerField::quantize(const FieldView& f, QuantizationRange keep) {
  const PointRange& pr = f.points;
  const int nx = pr.hi[0] - pr.lo[0], ny = pr.hi[1] - pr.lo[1], nz = pr.hi[2] - pr.lo[2];
  auto at = [&](int i, int j, int k) {
    return f.data[std::int64_t(i) * f.stride[0] + std::int64_t(j) * f.stride[1] + std::int64_t(k) * f.stride[2]];
  };
  // The value range (NaNs are left out; they quantize to q = 0).
  float vmin = std::numeric_limits<float>::infinity(), vmax = -vmin;
#pragma omp parallel for reduction(min : vmin) reduction(max : vmax) schedule(static)
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const float v = at(i, j, k);
        if (v < vmin) vmin = v;
        if (v > vmax) vmax = v;
      }
  if (!(vmin <= vmax)) vmin = vmax = 0;  // all NaN
  // Clamped to what the tasks tell apart; a field wholly on one side of it becomes that bound.
  if (vmax < keep.lo) vmin = vmax = keep.lo;
  else if (vmin > keep.hi) vmin = vmax = keep.hi;
  else vmin = std::max(vmin, keep.lo), vmax = std::min(vmax, keep.hi);
  offset_ = vmin;
  scale_ = (vmax - vmin) / 65535.0f;
  const float inv = scale_ > 0 ? 1.0f / scale_ : 0.0f;
  // Points first (each is read by up to eight cells), then the corner records.
  const std::size_t points = std::size_t(nx) * std::size_t(ny) * std::size_t(nz);
  Points pq(static_cast<std::uint16_t*>(allocate_huge(points * sizeof(std::uint16_t))),
            [](std::uint16_t* p) { deallocate_huge(p); });
#pragma omp parallel for schedule(static)
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const float v = at(i, j, k);
        const float u = ((v < vmin ? vmin : v > vmax ? vmax : v) - vmin) * inv + 0.5f;  // NaN stays NaN
        pq[std::size_t(i + std::int64_t(nx) * (j + std::int64_t(ny) * k))] =
            u >= 0 ? std::uint16_t(std::min(u, 65535.0f)) : std::uint16_t(0);  // also NaN → 0
      }
  return pq;
}

std::shared_ptr<std::uint16_t> CornerField::write_records(const std::uint16_t* const* pq, int nf, const FieldView& f,
                                                          const Index3& counts) {
  const PointRange& pr = f.points;
  const int nx = pr.hi[0] - pr.lo[0], ny = pr.hi[1] - pr.lo[1], nz = pr.hi[2] - pr.lo[2];
  const int cx = counts[0], cy = counts[1], cz = counts[2];
  const int rec = 8 * nf;
  const std::size_t values = std::size_t(cx) * std::size_t(cy) * std::size_t(cz) * std::size_t(rec);
  std::shared_ptr<std::uint16_t> q(static_cast<std::uint16_t*>(allocate_huge(values * sizeof(std::uint16_t))),
                                   [](std::uint16_t* p) { deallocate_huge(p); });
  std::uint16_t* const base = q.get();
#pragma omp parallel for schedule(static)
  for (int k = 0; k < cz; ++k)
    for (int j = 0; j < cy; ++j) {
      const int k1 = std::min(k + 1, nz - 1), j1 = std::min(j + 1, ny - 1);
      std::uint16_t* const row = base + std::size_t(rec) * std::size_t(std::int64_t(cx) * (j + std::int64_t(cy) * k));
      for (int s = 0; s < nf; ++s) {
        const std::uint16_t* const p = pq[s];
        const std::uint16_t* r00 = &p[std::size_t(std::int64_t(nx) * (j + std::int64_t(ny) * k))];
        const std::uint16_t* r10 = &p[std::size_t(std::int64_t(nx) * (j1 + std::int64_t(ny) * k))];
        const std::uint16_t* r01 = &p[std::size_t(std::int64_t(nx) * (j + std::int64_t(ny) * k1))];
        const std::uint16_t* r11 = &p[std::size_t(std::int64_t(nx) * (j1 + std::int64_t(ny) * k1))];
        std::uint16_t* out = row + 8 * s;
        for (int i = 0; i < cx; ++i, out += rec) {
          const int i1 = std::min(i + 1, nx - 1);
          out[0] = r00[i], out[1] = r00[i1], out[2] = r10[i], out[3] = r10[i1];
          out[4] = r01[i], out[5] = r01[i1], out[6] = r11[i], out[7] = r11[i1];
        }
      }
    }
  return q;
}

}  // namespace panoptes::render
