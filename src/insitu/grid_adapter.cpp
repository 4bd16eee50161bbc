#include "insitu/grid_adapter.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "core/error.hpp"
#include "insitu/halo.hpp"

namespace panoptes::insitu {
namespace {

std::string str(const render::Index3& v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

constexpr int kPackedBlock = 13;  // patch, offset, extent, ghost_lo, ghost_hi

void pack(const GridBlock& b, int* v) {
  v[0] = b.patch;
  for (int a = 0; a < 3; ++a) {
    v[1 + a] = b.offset[a];
    v[4 + a] = b.extent[a];
    v[7 + a] = b.ghost_lo[a];
    v[10 + a] = b.ghost_hi[a];
  }
}
GridBlock unpack(const int* v) {
  GridBlock b;
  b.patch = v[0];
  for (int a = 0; a < 3; ++a) {
    b.offset[a] = v[1 + a];
    b.extent[a] = v[4 + a];
    b.ghost_lo[a] = v[7 + a];
    b.ghost_hi[a] = v[10 + a];
  }
  return b;
}

// The grid's blocks must partition every patch: each point owned by exactly one block.
void check_partition(const grid::GridDescription& g, const std::vector<GridBlock>& blocks, const std::string& who) {
  const render::Index3 n = g.dims();
  std::vector<std::int64_t> owned(std::size_t(g.patches()), 0);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const GridBlock& x = blocks[b];
    const std::string name = who + " " + std::to_string(b);
    if (x.patch < 0 || x.patch >= g.patches())
      throw Error(name + ": patch " + std::to_string(x.patch) + "; the " + std::string(grid::to_string(g.kind)) +
                  " grid has patches 0" + (g.patches() > 1 ? " and 1 (Yin, Yang)" : " only"));
    for (int a = 0; a < 3; ++a) {
      if (x.offset[a] < 0 || x.extent[a] < 1 || x.offset[a] + x.extent[a] > n[a])
        throw Error(name + ": points " + str(x.offset) + " + " + str(x.extent) + " outside the grid's " + str(n) +
                    " points (or empty)");
      if (x.ghost_lo[a] < 0 || x.ghost_hi[a] < 0) throw Error(name + ": negative ghost layers");
    }
    std::int64_t size = 1;
    for (int a = 0; a < 3; ++a) size *= x.extent[a];
    owned[std::size_t(x.patch)] += size;
    for (std::size_t c = 0; c < b; ++c) {
      const GridBlock& y = blocks[c];
      bool meet = y.patch == x.patch;
      for (int a = 0; a < 3 && meet; ++a)
        meet = std::max(x.offset[a], y.offset[a]) < std::min(x.offset[a] + x.extent[a], y.offset[a] + y.extent[a]);
      if (meet)
        throw Error(name + " (patch " + std::to_string(x.patch) + ", points " + str(x.offset) + " + " + str(x.extent) +
                    ") overlaps " + who + " " + std::to_string(c) + " (" + str(y.offset) + " + " + str(y.extent) +
                    "): each point must be owned by exactly one block");
    }
  }
  for (int p = 0; p < g.patches(); ++p)
    if (owned[std::size_t(p)] != g.points_per_patch())
      throw Error("the blocks own " + std::to_string(owned[std::size_t(p)]) + " points of patch " + std::to_string(p) +
                  " of the " + g.summary() + " grid, which has " + std::to_string(g.points_per_patch()) +
                  ": a block is missing");
}

int default_points(const grid::GridDescription& g) {
  const render::Index3 n = g.dims();
  return std::clamp(std::max({n[0], n[1], n[2]}), 16, 1024);
}

render::GridGeometry cover_of(const grid::GridDescription& g, const ResampleOptions& o) {
  g.validate();
  if (o.longest_axis_points != 0 && (o.longest_axis_points < 2 || o.longest_axis_points > 4096))
    throw Error("resample points " + std::to_string(o.longest_axis_points) + "; expected 2 to 4096 (0 = automatic)");
  if (g.kind == grid::GridKind::uniform) return g.uniform;
  return grid::uniform_cover(g, o.longest_axis_points ? o.longest_axis_points : default_points(g));
}

}  // namespace

render::GridGeometry GridAdapter::cover(const grid::GridDescription& source, const ResampleOptions& options) {
  return cover_of(source, options);
}

std::int64_t GridAdapter::Box::size() const {
  std::int64_t s = 1;
  for (int a = 0; a < 3; ++a) s *= std::max(0, hi[a] - lo[a]);
  return s;
}

GridAdapter::GridAdapter(const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
                         const ResampleOptions& options)
    : source_(source),
      render_grid_(cover_of(source, options)),
      render_block_(LocalBlock::whole(render_grid_)),
      resampler_(source, render_grid_, {{0, 0, 0}, render_grid_.dims}, options.outside_value) {
  check_partition(source_, blocks, "block");
  mine_ = blocks;
  init({blocks}, {resampler_.needed()});
}

#ifdef PANOPTES_HAVE_MPI
namespace {
LocalBlock slab_of(const render::GridGeometry& g, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (size > g.dims[2] - 1)
    throw Error("grid stage: " + std::to_string(size) + " ranks for a uniform cover of " + std::to_string(g.dims[2]) +
                " points along z; expected at most one rank per cell layer (raise the resample points)");
  return LocalBlock::slab(g, 2, size, rank);
}
render::PointRange owned_range(const LocalBlock& b) {
  return {b.offset, {b.offset[0] + b.extent[0], b.offset[1] + b.extent[1], b.offset[2] + b.extent[2]}};
}
}  // namespace

GridAdapter::GridAdapter(const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
                         const ResampleOptions& options, MPI_Comm comm)
    : source_(source),
      render_grid_(cover_of(source, options)),
      render_block_(slab_of(render_grid_, comm)),
      resampler_(source, render_grid_, owned_range(render_block_), options.outside_value),
      comm_(comm) {
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  mine_ = blocks;
  // Every rank's blocks and what its slab reads, per patch.
  const int np = source_.patches();
  std::vector<int> counts(static_cast<std::size_t>(size_)), displs(static_cast<std::size_t>(size_));
  const int n_mine = int(blocks.size());
  MPI_Allgather(&n_mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  std::vector<int> packed(std::size_t(kPackedBlock) * blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) pack(blocks[b], packed.data() + kPackedBlock * b);
  int total = 0;
  for (int r = 0; r < size_; ++r) {
    displs[std::size_t(r)] = total * kPackedBlock;
    total += counts[std::size_t(r)];
  }
  std::vector<int> byte_counts(counts);
  for (int& c : byte_counts) c *= kPackedBlock;
  std::vector<int> all(std::size_t(total) * kPackedBlock);
  MPI_Allgatherv(packed.data(), int(packed.size()), MPI_INT, all.data(), byte_counts.data(), displs.data(), MPI_INT, comm);
  std::vector<int> need(static_cast<std::size_t>(6 * np));
  for (int p = 0; p < np; ++p)
    for (int a = 0; a < 3; ++a) {
      need[std::size_t(6 * p + a)] = resampler_.needed()[std::size_t(p)].lo[a];
      need[std::size_t(6 * p + 3 + a)] = resampler_.needed()[std::size_t(p)].hi[a];
    }
  std::vector<int> all_need(need.size() * std::size_t(size_));
  MPI_Allgather(need.data(), int(need.size()), MPI_INT, all_need.data(), int(need.size()), MPI_INT, comm);
  std::vector<std::vector<GridBlock>> by_rank(static_cast<std::size_t>(size_));
  std::vector<GridBlock> flat;
  std::vector<std::vector<render::PointRange>> needs(static_cast<std::size_t>(size_));
  for (int r = 0, b = 0; r < size_; ++r) {
    for (int c = 0; c < counts[std::size_t(r)]; ++c, ++b) {
      by_rank[std::size_t(r)].push_back(unpack(all.data() + std::size_t(b) * kPackedBlock));
      flat.push_back(by_rank[std::size_t(r)].back());
    }
    for (int p = 0; p < np; ++p) {
      render::PointRange x;
      for (int a = 0; a < 3; ++a) {
        x.lo[a] = all_need[need.size() * std::size_t(r) + std::size_t(6 * p + a)];
        x.hi[a] = all_need[need.size() * std::size_t(r) + std::size_t(6 * p + 3 + a)];
      }
      needs[std::size_t(r)].push_back(x);
    }
  }
  check_partition(source_, flat, "block");
  init(by_rank, needs);
}
#endif

// blocks_by_rank[r]: rank r's blocks; needs_by_rank[r]: what rank r's slab reads, per patch.
void GridAdapter::init(const std::vector<std::vector<GridBlock>>& blocks_by_rank,
                       const std::vector<std::vector<render::PointRange>>& needs_by_rank) {
  const std::size_t ranks = std::size_t(size_);
  send_.assign(ranks, {});
  send_block_.assign(ranks, {});
  recv_.assign(ranks, {});
  auto owned_box = [](const GridBlock& b) {
    Box x;
    x.patch = b.patch;
    for (int a = 0; a < 3; ++a) x.lo[a] = b.offset[a], x.hi[a] = b.offset[a] + b.extent[a];
    return x;
  };
  auto meet = [](Box x, const render::PointRange& r) {
    for (int a = 0; a < 3; ++a) x.lo[a] = std::max(x.lo[a], r.lo[a]), x.hi[a] = std::min(x.hi[a], r.hi[a]);
    return x;
  };
  // What each rank's blocks owe each rank: senders and receivers walk the sender's blocks in order.
  for (int r = 0; r < size_; ++r) {
    const std::vector<render::PointRange>& need_r = needs_by_rank[std::size_t(r)];
    const std::vector<GridBlock>& my_blocks = blocks_by_rank[std::size_t(rank_)];
    for (std::size_t m = 0; m < my_blocks.size(); ++m) {
      const Box x = meet(owned_box(my_blocks[m]), need_r[std::size_t(my_blocks[m].patch)]);
      if (x.size() > 0) {
        send_[std::size_t(r)].push_back(x);
        send_block_[std::size_t(r)].push_back(int(m));
      }
    }
    const std::vector<render::PointRange>& need_me = resampler_.needed();
    for (const GridBlock& b : blocks_by_rank[std::size_t(r)]) {
      const Box x = meet(owned_box(b), need_me[std::size_t(b.patch)]);
      if (x.size() > 0) recv_[std::size_t(r)].push_back(x);
    }
  }
  gathered_.assign(std::size_t(source_.patches()), {});
  for (int p = 0; p < source_.patches(); ++p) {
    const render::PointRange& n = resampler_.needed()[std::size_t(p)];
    gathered_[std::size_t(p)].assign(std::size_t(std::max<std::int64_t>(
                                         0, std::int64_t(n.hi[0] - n.lo[0]) * (n.hi[1] - n.lo[1]) * (n.hi[2] - n.lo[2]))),
                                     0.0f);
  }
  send_counts_.assign(ranks, 0);
  send_displs_.assign(ranks, 0);
  recv_counts_.assign(ranks, 0);
  recv_displs_.assign(ranks, 0);
  std::int64_t s = 0, q = 0;
  for (std::size_t r = 0; r < ranks; ++r) {
    std::int64_t ns = 0, nr = 0;
    for (const Box& x : send_[r]) ns += x.size();
    for (const Box& x : recv_[r]) nr += x.size();
    if (s + ns > INT32_MAX || q + nr > INT32_MAX) throw Error("grid stage: more than 2^31 source points to exchange");
    send_counts_[r] = int(ns), send_displs_[r] = int(s), s += ns;
    recv_counts_[r] = int(nr), recv_displs_[r] = int(q), q += nr;
    if (int(r) != rank_) received_points_ += nr;
  }
  send_buf_.resize(std::size_t(s));
  recv_buf_.resize(std::size_t(q));
}

std::vector<FieldInput> GridAdapter::adapt(const std::vector<FieldInput>& fields) {
  const auto t0 = std::chrono::steady_clock::now();
  // Group the inputs by name: one per block of this process, in order.
  std::vector<std::string> names;
  for (const FieldInput& f : fields)
    if (std::find(names.begin(), names.end(), f.name) == names.end()) names.push_back(f.name);
  outputs_.resize(names.size());
  std::vector<FieldInput> result;
  for (std::size_t f = 0; f < names.size(); ++f) {
    std::vector<const FieldInput*> per_block;
    for (const FieldInput& in : fields)
      if (in.name == names[f]) per_block.push_back(&in);
    if (per_block.size() != mine_.size())
      throw Error("grid stage: field \"" + names[f] + "\" given " + std::to_string(per_block.size()) +
                  " times; expected once per local block (" + std::to_string(mine_.size()) + ")");
    for (const FieldInput* in : per_block)
      if (!in->data) throw Error("grid stage: field \"" + names[f] + "\" has no data");
    // Pack what every rank reads from this process's blocks.
    std::size_t o = 0;
    for (std::size_t r = 0; r < send_.size(); ++r)
      for (std::size_t x = 0; x < send_[r].size(); ++x) {
        const Box& b = send_[r][x];
        const GridBlock& blk = mine_[std::size_t(send_block_[r][x])];
        const FieldInput& in = *per_block[std::size_t(send_block_[r][x])];
        LocalBlock lb;
        lb.extent = blk.extent;
        lb.ghost_lo = blk.ghost_lo;
        lb.ghost_hi = blk.ghost_hi;
        const std::array<std::int64_t, 3> st = halo::field_strides(lb, in.stride);
        for (int k = b.lo[2]; k < b.hi[2]; ++k)
          for (int j = b.lo[1]; j < b.hi[1]; ++j) {
            const std::int64_t row = std::int64_t(k - blk.offset[2]) * st[2] + std::int64_t(j - blk.offset[1]) * st[1];
            if (in.type == ScalarType::f32) {
              const float* d = static_cast<const float*>(in.data) + row;
              for (int i = b.lo[0]; i < b.hi[0]; ++i) send_buf_[o++] = d[std::int64_t(i - blk.offset[0]) * st[0]];
            } else {
              const double* d = static_cast<const double*>(in.data) + row;
              for (int i = b.lo[0]; i < b.hi[0]; ++i) send_buf_[o++] = float(d[std::int64_t(i - blk.offset[0]) * st[0]]);
            }
          }
      }
#ifdef PANOPTES_HAVE_MPI
    if (size_ > 1)
      MPI_Alltoallv(send_buf_.data(), send_counts_.data(), send_displs_.data(), MPI_FLOAT, recv_buf_.data(),
                    recv_counts_.data(), recv_displs_.data(), MPI_FLOAT, comm_);
    else
#endif
      recv_buf_ = send_buf_;
    // Unpack into the gathered source ranges, per patch.
    o = 0;
    for (std::size_t r = 0; r < recv_.size(); ++r)
      for (const Box& b : recv_[r]) {
        const render::PointRange& n = resampler_.needed()[std::size_t(b.patch)];
        const std::int64_t nx = n.hi[0] - n.lo[0], ny = n.hi[1] - n.lo[1];
        std::vector<float>& g = gathered_[std::size_t(b.patch)];
        for (int k = b.lo[2]; k < b.hi[2]; ++k)
          for (int j = b.lo[1]; j < b.hi[1]; ++j) {
            float* d = g.data() + (std::int64_t(k - n.lo[2]) * ny + (j - n.lo[1])) * nx - n.lo[0];
            for (int i = b.lo[0]; i < b.hi[0]; ++i) d[i] = recv_buf_[o++];
          }
      }
    std::vector<grid::SourceBlock> blocks;
    for (int p = 0; p < source_.patches(); ++p) {
      const render::PointRange& n = resampler_.needed()[std::size_t(p)];
      if (n.lo != n.hi) blocks.push_back(grid::SourceBlock::of(p, n, gathered_[std::size_t(p)].data()));
    }
    outputs_[f].resize(std::size_t(resampler_.size()));
    resampler_.resample(blocks, outputs_[f]);
    FieldInput out;
    out.name = names[f];
    out.data = outputs_[f].data();
    out.type = ScalarType::f32;
    result.push_back(out);
  }
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace panoptes::insitu
