// Subnormal values in the solver's fields (seismic/denormals.hpp): none are kept, and the caller's
// floating-point mode survives a step.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "seismic/solver.hpp"
#include "seismic/test_util.hpp"

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#endif

static const bool kSubnormalTestThreads = panoptes::seismic::test_util::default_single_thread();

using namespace panoptes::seismic;

namespace {

// An explosion in a small whole-space box: ahead of its front the stencils spread values that
// shrink through the subnormal range.
SolverConfig small_box(double M0 = 1e15) {
  SolverConfig cfg;
  const int n = 40;
  const double h = 10;
  cfg.grid = {n, n, n, h};
  cfg.medium = MediumSpec::homogeneous(2000, 1732.0508, 1000);
  cfg.boundary.free_surface = false;
  cfg.boundary.pml_cells = 8;
  const double c = n / 2 * h;
  cfg.sources = {SourceSpec::explosion({c, c, c}, M0, SourceTimeFunction::ricker(5.0))};
  return cfg;
}

}  // namespace

TEST(SeismicSubnormals, FieldsHoldNoSubnormalValues) {
  // Without the flush, steps 15-25 of this box hold thousands of subnormal values in the stresses
  // and velocities (9,114 at step 20); by step 40 the box is filled with normal ones.
  Solver s(small_box());
  long nonzero = 0;
  for (int round = 0; round < 5; ++round) {
    s.run(5);
    s.compute_derived();
    for (const std::string& name : Solver::field_names()) {
      long subnormal = 0;
      for (const float v : s.gather_field(name)) {
        subnormal += std::fpclassify(v) == FP_SUBNORMAL;
        nonzero += v != 0;
      }
      EXPECT_EQ(subnormal, 0) << name << " after step " << s.steps_done()
                              << ": subnormal values kept (each costs a microcode assist per operation)";
    }
  }
  EXPECT_GT(nonzero, 0) << "the source radiated nothing";
}

#if defined(__SSE2__) || defined(_M_X64)
TEST(SeismicSubnormals, TheCallersFloatingPointModeIsKept) {
  const unsigned before = _mm_getcsr();
  for (const unsigned mode : {before & ~0x8040u, before | 0x8040u}) {  // FTZ and DAZ off, then on
    _mm_setcsr(mode);
    Solver s(small_box());
    s.run(3);
    s.compute_derived();
    // The control bits (6-15: rounding, masks, FTZ, DAZ), not the sticky exception flags the step raises.
    EXPECT_EQ(_mm_getcsr() & ~0x3fu, mode & ~0x3fu) << "the solver left the calling thread's floating-point mode changed";
  }
  _mm_setcsr(before);
}
#endif
