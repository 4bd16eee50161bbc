#pragma once
// The in-situ grid stage (issue 33): a simulation whose grid is not a uniform box (rectilinear,
// spherical shell, Yin-Yang; grid/grid_description.hpp) hands its local blocks to a GridAdapter,
// which gathers the source points each rank's render brick needs from their owners (one MPI
// all-to-all per field and snapshot) and resamples them (grid::Resampler) onto that rank's slab of
// a uniform cover of the domain. The Session then renders the slabs as it renders any uniform grid.
#include <array>
#include <cstdint>
#include <vector>

#include "grid/grid_description.hpp"
#include "grid/resampler.hpp"
#include "insitu/session.hpp"

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::insitu {

/// This rank's block of a source grid: the points [offset, offset + extent) of patch `patch`'s
/// index space (Yin-Yang: 0 = Yin, 1 = Yang; other grids: 0) and the ghost layers its arrays store
/// around them. Only owned points are read; the blocks of all ranks must partition every patch.
struct GridBlock {
  int patch = 0;
  render::Index3 offset{0, 0, 0};
  render::Index3 extent{0, 0, 0};
  render::Index3 ghost_lo{0, 0, 0};
  render::Index3 ghost_hi{0, 0, 0};
  /// A whole patch, no ghosts.
  static GridBlock whole(const grid::GridDescription& g, int patch = 0) { return {patch, {0, 0, 0}, g.dims(), {}, {}}; }
};

/// How the adapter resamples: points along the longest axis of the uniform cover (0 = the source's
/// largest dimension) and the value of points outside the source's domain.
struct ResampleOptions {
  int longest_axis_points = 0;
  float outside_value = 0;
};

/// The grid stage of one rank. Construction is collective (it gathers every rank's block and what
/// each rank's slab reads); adapt() is collective when any rank reads points another rank owns.
class GridAdapter {
 public:
  /// Single process: `blocks` partition every patch (Yin-Yang: at least one block of Yin and one of
  /// Yang). Throws panoptes::Error on an invalid grid, block or partition.
  GridAdapter(const grid::GridDescription& source, const std::vector<GridBlock>& blocks, const ResampleOptions& options);
#ifdef PANOPTES_HAVE_MPI
  /// `blocks`: this rank's blocks (usually one); the blocks of all ranks of `comm` partition every
  /// patch. `comm` is used during construction and by adapt() (not duplicated). Each rank renders
  /// slab `rank` of `size` along z of the uniform cover.
  GridAdapter(const grid::GridDescription& source, const std::vector<GridBlock>& blocks, const ResampleOptions& options,
              MPI_Comm comm);
#endif

  /// The uniform grid a source grid is resampled onto (what render_grid() will be), checking the
  /// source and the options first: throws panoptes::Error naming the bad value. Local (no collective):
  /// the session agrees on its outcome before the constructor's collectives.
  static render::GridGeometry cover(const grid::GridDescription& source, const ResampleOptions& options);
  /// How many of this rank's blocks each field is given for (adapt()'s `fields`: one input per block).
  int block_count() const { return int(mine_.size()); }
  /// The uniform grid the session renders, and this rank's slab of it (no ghosts: the session
  /// fetches its ghost points from the neighbouring slabs).
  const render::GridGeometry& render_grid() const { return render_grid_; }
  const LocalBlock& render_block() const { return render_block_; }
  const grid::GridDescription& source() const { return source_; }
  const grid::Resampler& resampler() const { return resampler_; }

  /// The fields on this rank's slab, as float32 inputs pointing into the adapter's buffers (valid
  /// until the next call). `fields` holds one input per field and local block (FieldInput rules:
  /// data at the block's first owned point; stride {0,0,0} = contiguous over the ghosted block); a
  /// single process holding several blocks (Yin and Yang) passes each field once per block, in
  /// the blocks' order. Throws panoptes::Error on a missing or duplicated field.
  std::vector<FieldInput> adapt(const std::vector<FieldInput>& fields);
  /// Wall seconds spent in adapt() (gathering + resampling) since construction.
  double seconds() const { return seconds_; }
  /// Source points this rank received from other ranks per field and snapshot.
  std::int64_t received_points() const { return received_points_; }

 private:
  struct Box {
    int patch = 0;
    render::Index3 lo{0, 0, 0}, hi{0, 0, 0};
    std::int64_t size() const;
  };
  void init(const std::vector<std::vector<GridBlock>>& blocks_by_rank,
            const std::vector<std::vector<render::PointRange>>& needs_by_rank);

  grid::GridDescription source_;
  render::GridGeometry render_grid_;
  LocalBlock render_block_;
  grid::Resampler resampler_;
  int rank_ = 0, size_ = 1;
#ifdef PANOPTES_HAVE_MPI
  MPI_Comm comm_ = MPI_COMM_NULL;
#endif
  std::vector<GridBlock> mine_;                  // this rank's blocks
  std::vector<std::vector<Box>> send_;           // [rank]: boxes of my blocks' points rank needs (my block index in patch)
  std::vector<std::vector<int>> send_block_;     // [rank]: which of mine_ each send box reads
  std::vector<std::vector<Box>> recv_;           // [rank]: boxes I receive from rank
  std::vector<std::vector<float>> gathered_;     // [patch]: over needed()[patch]
  std::vector<std::vector<float>> outputs_;      // [field]: the resampled slab
  std::vector<float> send_buf_, recv_buf_;
  std::vector<int> send_counts_, send_displs_, recv_counts_, recv_displs_;
  double seconds_ = 0;
  std::int64_t received_points_ = 0;
};

}  // namespace panoptes::insitu
