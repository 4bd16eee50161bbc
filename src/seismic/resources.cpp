#include "seismic/resources.hpp"

#include <algorithm>
#include <cmath>

namespace panoptes::seismic {

MemoryEstimate estimate_solver_memory(const SolverConfig& c, int ranks) {
  ranks = std::max(ranks, 1);
  const double G = 2;  // ghost layers of every array (solver.cpp)
  const double nx = c.grid.nx, ny = c.grid.ny, nz = c.grid.nz;
  const double nzl = std::ceil(nz / ranks);
  const double N = (nx + 2 * G) * (ny + 2 * G) * (nzl + 2 * G);  // elements of one ghosted array
  const double n = nx * ny * (nzl + 1);                           // nodes of the sampled medium block
  bool attenuating = std::isfinite(c.medium.qp) || std::isfinite(c.medium.qs) || !c.medium.qp_file.empty() ||
                     !c.medium.qs_file.empty();
  for (const Layer& l : c.medium.layers) attenuating = attenuating || std::isfinite(l.qp) || std::isfinite(l.qs);
  const double L = attenuating ? std::max(c.attenuation.mechanisms, 3) : 0;
  const double K = 8 + 5 * L;  // material coefficients per node
  MemoryEstimate e;
  e.add("wavefield arrays", 9 * 4 * N);
  e.add("derived fields", 2 * 4 * N);
  if (L > 0) e.add("memory variables", 6 * L * 4 * N);
  // Layered media share a table of distinct coefficient tuples (2-byte ids per node); file media may
  // need one dense array per coefficient (more than 65,536 distinct tuples).
  e.add("material coefficients", c.medium.kind == MediumSpec::Kind::file ? K * 4 * N : 2 * N);
  // Freed after setup, but alive together with the arrays above while the solver is built: the
  // sampled medium (5 floats per node) and the unrelaxed moduli and relaxation weights (doubles).
  e.add("medium setup", n * (5 * 4 + 3 * 8 + 2 * 8 * L));
  const double p = 2.0 * c.boundary.pml_cells;
  e.add("absorbing layers", 6 * 4 * p * ((ny + 2 * G) * (nzl + 2 * G) + (nx + 2 * G) * (nzl + 2 * G) + (nx + 2 * G) * (ny + 2 * G)));
  const double samples = std::floor(double(c.steps) / std::max(c.record_every, 1)) + 2;
  // The time axis of the traces is reserved for every step even without receivers.
  e.add("receiver traces", (1 + 3.0 * double(c.receivers.size())) * 8 * samples);
  // Per-item tables (issue #31: 10^5 [[source]] tables took 8.8 GB unseen by this estimate). Each
  // point source is spread over up to 8x8x8 nodes per component it drives (solver.cpp, Kaiser sinc):
  // one 40-byte Injection per node, kept twice (the list and its copy sorted by row), for 6 stress
  // components (moment) or 3 velocity components (force); plus the two copies of the SourceSpec.
  double injections = 0;
  for (const SourceSpec& s : c.sources) injections += s.kind == SourceSpec::Kind::moment ? 6 * 512 : 3 * 512;
  if (!c.sources.empty()) e.add("source tables", 2 * 40 * injections + 2 * double(sizeof(SourceSpec)) * double(c.sources.size()));
  // Receivers: the spec (name and position), 3 components x 8 interpolation weights and indices.
  double receiver_bytes = 0;
  for (const ReceiverSpec& r : c.receivers) receiver_bytes += double(sizeof(ReceiverSpec) + r.name.size()) + 3 * 8 * 16;
  if (!c.receivers.empty()) e.add("receiver tables", receiver_bytes);
  return e;
}

}  // namespace panoptes::seismic
