#include "seismic/solver.hpp"

#include <cmath>

#include "seismic/solver_impl.hpp"

namespace panoptes::seismic {

double stable_time_step(double h, double vp_max) {
  return h / (std::sqrt(3.0) * (9.0 / 8.0 + 1.0 / 24.0) * vp_max);
}

// ==================================================================== public API

Solver::Solver(const SolverConfig& config) : impl_(std::make_unique<Impl>()) {
#ifdef PANOPTES_HAVE_MPI
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) {
    impl_->comm = MPI_COMM_WORLD;
    MPI_Comm_rank(MPI_COMM_WORLD, &impl_->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &impl_->size);
  }
#endif
  impl_->init(config);
}

#ifdef PANOPTES_HAVE_MPI
Solver::Solver(const SolverConfig& config, MPI_Comm comm) : impl_(std::make_unique<Impl>()) {
  impl_->comm = comm;
  MPI_Comm_rank(comm, &impl_->rank);
  MPI_Comm_size(comm, &impl_->size);
  impl_->init(config);
}
#endif

Solver::~Solver() = default;

void Solver::step() { impl_->step(); }
void Solver::run(int n) {
  for (int i = 0; i < n; ++i) impl_->step();
}
int Solver::steps_done() const { return impl_->nsteps; }
double Solver::dt() const { return impl_->dt; }
double Solver::velocity_time() const { return (impl_->nsteps - 0.5) * impl_->dt; }
const SolverConfig& Solver::config() const { return impl_->cfg; }
int Solver::rank() const { return impl_->rank; }
int Solver::ranks() const { return impl_->size; }
int Solver::k_begin() const { return impl_->kb; }
int Solver::k_end() const { return impl_->ke; }
bool Solver::viscoelastic() const { return impl_->L > 0; }
double Solver::vp_max() const { return impl_->vpmax; }


FieldView Solver::vx() const { return impl_->view(impl_->vx, {0.5, 0, 0}); }
FieldView Solver::vy() const { return impl_->view(impl_->vy, {0, 0.5, 0}); }
FieldView Solver::vz() const { return impl_->view(impl_->vz, {0, 0, 0.5}); }
FieldView Solver::phi_p() const { return impl_->view(impl_->phip, {0, 0, 0}); }
FieldView Solver::phi_s() const { return impl_->view(impl_->phis, {0, 0, 0}); }

std::size_t Solver::memory_bytes() const {
  const Impl& s = *impl_;
  std::size_t b = 9 * s.N * sizeof(float);                              // fields
  b += std::size_t(s.L) * 6 * s.N * sizeof(float);                      // memory variables
  b += s.mat_id.size() * sizeof(std::uint16_t) + s.mat_tab.size() * sizeof(float);
  for (const auto& v : s.mat_dense) b += v.size() * sizeof(float);
  for (const auto* p : {&s.psix, &s.psiy, &s.psiz})
    for (const auto& v : *p) b += v.size() * sizeof(float);
  b += s.phip.size() * 2 * sizeof(float);
  return b;
}

}  // namespace panoptes::seismic
