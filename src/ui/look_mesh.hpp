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

}  // namespace panoptes::ui
