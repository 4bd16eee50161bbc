#pragma once
// Ghost points ("halos") of the ranks' blocks: which points of a rank's arrays the session may read,
// and the exchange that fetches every other point its brick needs from the rank that owns it.
//
// A simulation's arrays hold STORED ghost layers (LocalBlock::ghost_lo/hi), of which only the VALID
// ones (valid_lo/hi) are kept up to date, and usually only by a face exchange: edge and corner ghosts
// (outside the owned box on two or three axes) then hold whatever was there before (DESIGN.md
// decision 12: never read them). A rank reads from its own arrays its owned points and the ghost
// points of its trusted boxes; every other point of its required range comes from its owner.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "insitu/session.hpp"
#include "render/field_view.hpp"

namespace panoptes::insitu::halo {

/// A box of global point indices [lo, hi).
struct Box {
  render::Index3 lo{0, 0, 0}, hi{0, 0, 0};
  bool empty() const { return hi[0] <= lo[0] || hi[1] <= lo[1] || hi[2] <= lo[2]; }
  std::int64_t size() const {
    return empty() ? 0 : std::int64_t(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  }
  bool contains(const Box& o) const {
    for (int a = 0; a < 3; ++a)
      if (o.lo[a] < lo[a] || o.hi[a] > hi[a]) return false;
    return true;
  }
};
Box intersect(const Box& a, const Box& b);

/// What every rank knows about every rank's block.
struct BlockInfo {
  LocalBlock block;
  Box owned;     ///< owned points
  Box required;  ///< the ghosted point range its brick needs (empty brick: empty)
  /// Boxes whose points the rank's arrays hold valid values for: the owned box grown by the valid
  /// layers along one axis each (face halos), or one box grown along all axes (edges_valid).
  std::vector<Box> trusted;
  render::Brick brick;
  bool has_brick = false;
  /// True when every point of `x` lies in one trusted box, i.e. may be read from this rank's arrays.
  bool trusts(const Box& x) const;
};

/// Checks one rank's block against the grid (offset, extent, ghosts, valid layers); throws Error
/// naming the rank, the member (e.g. `valid_lo`), the axis, the value and what was expected.
void validate_block(const LocalBlock& b, int rank, const render::GridGeometry& g);
/// The block's boxes (validate_block() first).
BlockInfo block_info(const render::GridGeometry& g, const LocalBlock& b);

/// Integers per block in the all-gather of block descriptions.
inline constexpr int kPackedInts = 19;
std::array<int, kPackedInts> pack_block(const LocalBlock& b);
LocalBlock unpack_block(const int* v);

/// Element strides of a field over the block's stored (ghosted) box; {0,0,0} in `stride` means
/// contiguous x-fastest.
std::array<std::int64_t, 3> field_strides(const LocalBlock& b, const std::array<std::int64_t, 3>& stride);

/// True when rank r needs points from rank s through the exchange (s owns some of r's required
/// points that r does not trust).
bool fetches(const std::vector<BlockInfo>& blocks, int r, int s);

/// The per-snapshot field gathering of one rank (built once by the session from every rank's block).
struct Exchange {
  const std::vector<BlockInfo>* blocks = nullptr;  ///< every rank's block, in rank order
  int rank = 0, size = 1;
  bool needed = false;  ///< some rank fetches from another: load() is then collective over `comm`
#ifdef PANOPTES_HAVE_MPI
  MPI_Comm comm = MPI_COMM_NULL;
#endif
  /// Fills `out` (one float32 buffer per field, x-fastest over `region`, sized by the caller) with
  /// this rank's fields over `region`: the points it trusts from its arrays (`inputs`, one per
  /// field), the others received from their owners; meanwhile sends every other rank what it
  /// fetches from this one.
  void load(const std::vector<const FieldInput*>& inputs, const Box& region, std::vector<std::vector<float>>& out);

 private:
  // The messages' buffers, one per peer, kept from one snapshot to the next: fresh ones cost a page fault
  // per 4 KiB and a zero fill each snapshot (issue 45, the cameras split so that every rank gathers the
  // whole grid: memset 0.74 -> 0.53 % and clear_page 0.26 -> 0.15 % of the run's samples, Panoptes ~25 %).
  std::vector<std::vector<float>> sends_, receives_;
};

}  // namespace panoptes::insitu::halo
