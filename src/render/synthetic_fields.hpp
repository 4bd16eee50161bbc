#pragma once
// Synthetic fields with known structure: test scenes, benchmarks and demos without a simulation.
#include <span>
#include <vector>

#include "render/field_view.hpp"

namespace panoptes::render {

/// An expanding spherical wave front: a Ricker-wavelet shell of radius `radius` and half-width
/// `width` (world units) around `centre`: amplitude·(1 − 2u²)·exp(−u²), u = (r − radius)/width.
struct WaveFront {
  Vec3 centre;
  double radius = 1;
  double width = 1;
  double amplitude = 1;
};

/// The sum of the wave fronts sampled at every grid point, x fastest (shape [nz][ny][nx]);
/// OpenMP-parallel. Values are signed (the wavelet has negative side lobes).
std::vector<float> wave_field(const GridGeometry& grid, std::span<const WaveFront> fronts);

}  // namespace panoptes::render
