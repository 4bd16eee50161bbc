#pragma once
// The look-around view of a 360° (equirectangular) frame on the GPU: a grid of triangles covering the
// window whose texture coordinates are the (longitude, latitude) of each vertex's viewing ray, drawn
// with SDL_RenderGeometry over the frame's YUV texture. The GPU interpolates texture coordinates and
// samples (and converts) the YUV texture, so the display path stays free of per-pixel CPU work.
// Triangles that straddle the ±180° seam are clipped into two pieces, one on each side of the texture.
#include <vector>

#include "player/look.hpp"

namespace panoptes::ui {

/// One mesh vertex: screen position (pixels) and texture coordinate (0..1 over the equirectangular frame).
struct MeshVertex {
  float x = 0, y = 0, u = 0, v = 0;
};

/// Fills `triangles` (3 vertices each) for the perspective view `look` of a camera with frame `camera`
/// into the screen rectangle (x0, y0, w, h), on a grid of cells_x x cells_y cells. Reuses the vector's
/// memory. The texture coordinates at the vertices are exact (as player::perspective_cutout); between
/// them they are linear, within a fraction of a source pixel for the default grid at fov <= 120°.
void build_look_mesh(const player::ViewBasis& camera, const player::Look& look, float x0, float y0, float w, float h,
                     std::vector<MeshVertex>& triangles, int cells_x = 96, int cells_y = 72);

/// The worst distance, in pixels of a `source_width` x `source_width / 2` frame, between the linear
/// texture coordinates at the triangles' centroids and the exact mapping there.
double look_mesh_error(const player::ViewBasis& camera, const player::Look& look, float x0, float y0, float w, float h,
                       const std::vector<MeshVertex>& triangles, int source_width);

/// build_look_mesh() on the coarsest grid that keeps look_mesh_error() within half a source pixel:
/// starting from an estimate for the field of view and the source width (the error of a cell grows with
/// the source's pixels per radian times the square of the cell's angle) and refined by half until it
/// fits or reaches 128 cells per side (the poles in view need the most). A 768-pixel frame in a 2:1
/// window at 90° gets about half the triangles of the old fixed 96 x 72 grid, and the software GL
/// rasteriser pays per triangle (docs/ui.md). Returns the grid's cells along x (and y in `cells_y`).
int build_fitted_look_mesh(const player::ViewBasis& camera, const player::Look& look, float x0, float y0, float w,
                           float h, int source_width, std::vector<MeshVertex>& triangles, int* cells_y = nullptr);

}  // namespace panoptes::ui
