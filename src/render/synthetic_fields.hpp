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

/// A smooth standing wave filling the whole grid: amplitude·cos(2π·x/λx + φx)·cos(…y…)·cos(…z…)
/// in world coordinates (a wavelength of 0 makes that factor 1).
struct StandingWave {
  Vec3 wavelength;
  Vec3 phase;
  double amplitude = 1;
};

/// The sum of the wave fronts sampled at every grid point, x fastest (shape [nz][ny][nx]);
/// OpenMP-parallel. Values are signed (the wavelet has negative side lobes).
std::vector<float> wave_field(const GridGeometry& grid, std::span<const WaveFront> fronts);
/// The same plus standing waves (a field whose waves fill the box).
std::vector<float> wave_field(const GridGeometry& grid, std::span<const WaveFront> fronts,
                              std::span<const StandingWave> standing);

/// The dense "late-time snapshot" scene of the paper's setting, scaled to any grid: p and s
/// fields made of several spherical shells from three sources plus standing waves, so that most of
/// the box holds visible waves (with the p-wave / s-wave presets over a window of the 99.9th
/// percentile of |v|, more than half of the points are above the 10 % opacity threshold).
struct DenseWaveScene {
  std::vector<float> p, s;
};
DenseWaveScene dense_wave_scene(const GridGeometry& grid);

}  // namespace panoptes::render
