#pragma once
// What a seismic run will hold in memory, per rank, before it allocates any of it.
#include "core/memory.hpp"
#include "seismic/config.hpp"

namespace panoptes::seismic {

/// Peak resident bytes of one rank of Solver(config) on `ranks` z-slabs (the largest slab), itemized:
/// wavefield and derived-field arrays, memory variables, material tables, the medium sampled during
/// setup, CPML arrays and receiver traces (preallocated for every step). The model counts the
/// arrays Solver allocates (docs/seismic.md, "Memory"); config must have passed validate().
MemoryEstimate estimate_solver_memory(const SolverConfig& config, int ranks);

}  // namespace panoptes::seismic
