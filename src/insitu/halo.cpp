#include "insitu/halo.hpp"

#include <algorithm>
#include <utility>

#include "core/error.hpp"

namespace panoptes::insitu::halo {

Box intersect(const Box& a, const Box& b) {
  Box r;
  for (int i = 0; i < 3; ++i) {
    r.lo[i] = std::max(a.lo[i], b.lo[i]);
    r.hi[i] = std::min(a.hi[i], b.hi[i]);
  }
  return r;
}

bool BlockInfo::trusts(const Box& x) const {
  for (const Box& t : trusted)
    if (t.contains(x)) return true;
  return false;
}

void validate_block(const LocalBlock& b, int rank, const render::GridGeometry& g) {
  const std::string who = "local block of rank " + std::to_string(rank) + ": ";
  static const char* axis_name[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const std::string on = " on axis " + std::string(axis_name[a]);
    if (b.offset[a] < 0 || b.extent[a] < 0 || b.offset[a] + b.extent[a] > g.dims[a])
      throw Error(who + "offset " + std::to_string(b.offset[a]) + ", extent " + std::to_string(b.extent[a]) + on +
                  " lies outside the grid of " + std::to_string(g.dims[a]) + " points");
    if (b.ghost_lo[a] < 0 || b.ghost_hi[a] < 0)
      throw Error(who + "ghost_lo/ghost_hi " + std::to_string(b.ghost_lo[a]) + "/" + std::to_string(b.ghost_hi[a]) + on +
                  ": expected stored ghost layers >= 0");
    const std::pair<const char*, std::pair<int, int>> valid[2] = {{"valid_lo", {b.valid_lo[a], b.ghost_lo[a]}},
                                                                  {"valid_hi", {b.valid_hi[a], b.ghost_hi[a]}}};
    for (const auto& [name, v] : valid)
      if (v.first < -1 || v.first > v.second)
        throw Error(who + name + " = " + std::to_string(v.first) + on + ": expected -1 (every stored layer) or 0.." +
                    std::to_string(v.second) + " (the ghost layers stored on that side)");
  }
}

BlockInfo block_info(const render::GridGeometry& g, const LocalBlock& b) {
  BlockInfo bi;
  bi.block = b;
  Box grown;  // owned + valid layers on every axis, clipped to the grid
  for (int a = 0; a < 3; ++a) {
    bi.owned.lo[a] = b.offset[a];
    bi.owned.hi[a] = b.offset[a] + b.extent[a];
    const int vlo = b.valid_lo[a] < 0 ? b.ghost_lo[a] : b.valid_lo[a];
    const int vhi = b.valid_hi[a] < 0 ? b.ghost_hi[a] : b.valid_hi[a];
    grown.lo[a] = std::max(0, bi.owned.lo[a] - vlo);
    grown.hi[a] = std::min(g.dims[a], bi.owned.hi[a] + vhi);
    // Owned points [o, o+e) own the cells [o, min(o+e, dims−1)): the cell boxes of a point partition
    // partition the cells.
    bi.brick.lo[a] = b.offset[a];
    bi.brick.hi[a] = std::min(b.offset[a] + b.extent[a], g.dims[a] - 1);
  }
  if (b.edges_valid) {
    bi.trusted.push_back(grown);
  } else {
    // A face exchange fills the ghosts beside each face: points outside the owned box along one axis only.
    for (int a = 0; a < 3; ++a) {
      Box face = bi.owned;
      face.lo[a] = grown.lo[a];
      face.hi[a] = grown.hi[a];
      bi.trusted.push_back(face);
    }
  }
  bi.has_brick = bi.brick.cells() > 0 && bi.brick.hi[0] > bi.brick.lo[0] && bi.brick.hi[1] > bi.brick.lo[1] &&
                 bi.brick.hi[2] > bi.brick.lo[2];
  if (bi.has_brick) {
    const render::PointRange pr = render::required_points(g, bi.brick);
    bi.required.lo = pr.lo;
    bi.required.hi = pr.hi;
  }
  return bi;
}

std::array<int, kPackedInts> pack_block(const LocalBlock& b) {
  std::array<int, kPackedInts> v{};
  for (int a = 0; a < 3; ++a) {
    v[std::size_t(a)] = b.offset[a];
    v[std::size_t(3 + a)] = b.extent[a];
    v[std::size_t(6 + a)] = b.ghost_lo[a];
    v[std::size_t(9 + a)] = b.ghost_hi[a];
    v[std::size_t(12 + a)] = b.valid_lo[a];
    v[std::size_t(15 + a)] = b.valid_hi[a];
  }
  v[18] = b.edges_valid ? 1 : 0;
  return v;
}

LocalBlock unpack_block(const int* v) {
  LocalBlock b;
  for (int a = 0; a < 3; ++a) {
    b.offset[a] = v[a];
    b.extent[a] = v[3 + a];
    b.ghost_lo[a] = v[6 + a];
    b.ghost_hi[a] = v[9 + a];
    b.valid_lo[a] = v[12 + a];
    b.valid_hi[a] = v[15 + a];
  }
  b.edges_valid = v[18] != 0;
  return b;
}

std::array<std::int64_t, 3> field_strides(const LocalBlock& b, const std::array<std::int64_t, 3>& stride) {
  if (stride[0] != 0 || stride[1] != 0 || stride[2] != 0) return stride;
  const std::int64_t nx = b.extent[0] + b.ghost_lo[0] + b.ghost_hi[0];
  const std::int64_t ny = b.extent[1] + b.ghost_lo[1] + b.ghost_hi[1];
  return {1, nx, nx * ny};
}

bool fetches(const std::vector<BlockInfo>& blocks, int r, int s) {
  if (r == s) return false;
  const BlockInfo& br = blocks[std::size_t(r)];
  if (!br.has_brick) return false;
  const Box x = intersect(blocks[std::size_t(s)].owned, br.required);
  return !x.empty() && !br.trusts(x);
}

namespace {

// Copies box `x` of a rank's field (its arrays, addressed from the first owned point) into `out`,
// float32 x-fastest over `region`.
void copy_box(const LocalBlock& block, const FieldInput& in, const Box& x, const Box& region, float* out) {
  const std::array<std::int64_t, 3> st = field_strides(block, in.stride);
  const std::int64_t rx = region.hi[0] - region.lo[0], ry = region.hi[1] - region.lo[1];
  const bool dbl = in.type == ScalarType::f64;
  const auto* pf = static_cast<const float*>(in.data);
  const auto* pd = static_cast<const double*>(in.data);
#pragma omp parallel for collapse(2) schedule(static)
  for (int k = x.lo[2]; k < x.hi[2]; ++k)
    for (int j = x.lo[1]; j < x.hi[1]; ++j) {
      float* row = out + (std::int64_t(k - region.lo[2]) * ry + (j - region.lo[1])) * rx - region.lo[0];
      const std::int64_t base = std::int64_t(j - block.offset[1]) * st[1] + std::int64_t(k - block.offset[2]) * st[2];
      for (int i = x.lo[0]; i < x.hi[0]; ++i) {
        const std::int64_t idx = base + std::int64_t(i - block.offset[0]) * st[0];
        row[i] = dbl ? float(pd[idx]) : pf[idx];
      }
    }
}

}  // namespace

void Exchange::load(const std::vector<const FieldInput*>& inputs, const Box& region,
                    std::vector<std::vector<float>>& out) {
  const std::vector<BlockInfo>& all = *blocks;
  const BlockInfo& me = all[std::size_t(rank)];
  const std::size_t nf = inputs.size();
  // From this rank's arrays: the owned points, and whole neighbour overlaps it trusts.
  std::vector<Box> local{intersect(me.owned, region)};
  for (int s = 0; s < size; ++s) {
    if (s == rank) continue;
    const Box x = intersect(all[std::size_t(s)].owned, region);
    if (!x.empty() && !fetches(all, rank, s)) local.push_back(x);
  }
  for (std::size_t f = 0; f < nf; ++f)
    for (const Box& x : local)
      if (!x.empty()) copy_box(me.block, *inputs[f], x, region, out[f].data());
#ifdef PANOPTES_HAVE_MPI
  if (!needed || size < 2) return;
  // Rank s sends rank r the points it owns in r's required range whenever r does not trust them.
  // Everyone knows every block, so the pattern needs no handshake.
  std::vector<MPI_Request> reqs;
  sends_.resize(std::size_t(size));
  receives_.resize(std::size_t(size));
  for (int r = 0; r < size; ++r) {
    if (!fetches(all, r, rank)) continue;
    const Box x = intersect(me.owned, all[std::size_t(r)].required);
    std::vector<float>& pack = sends_[std::size_t(r)];
    pack.resize(std::size_t(x.size()) * nf);  // every element written below
    for (std::size_t f = 0; f < nf; ++f) copy_box(me.block, *inputs[f], x, x, pack.data() + std::size_t(x.size()) * f);
    reqs.emplace_back();
    MPI_Isend(pack.data(), int(pack.size()), MPI_FLOAT, r, 7, comm, &reqs.back());
  }
  for (int s = 0; s < size; ++s) {
    if (!fetches(all, rank, s)) continue;
    const Box x = intersect(all[std::size_t(s)].owned, me.required);
    std::vector<float>& data = receives_[std::size_t(s)];
    data.resize(std::size_t(x.size()) * nf);
    reqs.emplace_back();
    MPI_Irecv(data.data(), int(data.size()), MPI_FLOAT, s, 7, comm, &reqs.back());
  }
  MPI_Waitall(int(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
  const std::int64_t rx = region.hi[0] - region.lo[0], ry = region.hi[1] - region.lo[1];
  for (int s = 0; s < size; ++s) {
    if (!fetches(all, rank, s)) continue;
    const Box x = intersect(all[std::size_t(s)].owned, me.required);
    const float* p = receives_[std::size_t(s)].data();
    const std::size_t row = std::size_t(x.hi[0] - x.lo[0]);
    for (std::size_t f = 0; f < nf; ++f)
      for (int k = x.lo[2]; k < x.hi[2]; ++k)
        for (int j = x.lo[1]; j < x.hi[1]; ++j, p += row)
          std::copy_n(p, row, &out[f][std::size_t((std::int64_t(k - region.lo[2]) * ry + (j - region.lo[1])) * rx + (x.lo[0] - region.lo[0]))]);
  }
#endif
}

}  // namespace panoptes::insitu::halo
