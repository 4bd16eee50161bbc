#pragma once
// Subnormal floats in the solver (docs/seismic.md, "Subnormal values"): a scoped switch of the calling
// thread's floating-point unit to flush them to zero, restored on leaving the scope.
#include <cstdint>

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#define PANOPTES_DENORMALS_X86 1
#elif defined(__aarch64__)
#define PANOPTES_DENORMALS_ARM64 1
#endif

namespace panoptes::seismic {

/// While alive, the calling thread treats subnormal operands as zero and flushes subnormal results
/// to zero (x86: MXCSR's DAZ and FTZ bits; AArch64: FPCR.FZ); the destructor restores the mode it found
/// (the exception flags raised meanwhile are kept).
/// Why: ahead of every wavefront the stencils spread values that shrink through the subnormal range
/// (|x| < 1.2e-38), and on x86 each operation on one takes a microcode assist of ~100 cycles; early in
/// the paper's run most of the grid is in that state (steps up to 3x slower). Such values are far
/// below what a float field resolves beside its signal (relative 1e-7); flushing them changes the
/// fields only by rounding noise (docs/seismic.md, "Subnormal values"). Scoped, not process-wide: the
/// solver is a library and the caller's own code keeps its mode. Construct one per thread (in each
/// OpenMP parallel region), as the mode is per thread.
class FlushSubnormals {
 public:
  FlushSubnormals() noexcept {
#if defined(PANOPTES_DENORMALS_X86)
    saved_ = _mm_getcsr();
    _mm_setcsr(saved_ | kDaz | kFtz);
#elif defined(PANOPTES_DENORMALS_ARM64)
    saved_ = __builtin_aarch64_get_fpcr64();
    __builtin_aarch64_set_fpcr64(saved_ | kFz);
#endif
  }
  ~FlushSubnormals() {
#if defined(PANOPTES_DENORMALS_X86)
    _mm_setcsr((_mm_getcsr() & kFlags) | (saved_ & ~kFlags));  // the mode back; exceptions raised since stay raised
#elif defined(PANOPTES_DENORMALS_ARM64)
    __builtin_aarch64_set_fpcr64(saved_);
#endif
  }
  FlushSubnormals(const FlushSubnormals&) = delete;
  FlushSubnormals& operator=(const FlushSubnormals&) = delete;

 private:
#if defined(PANOPTES_DENORMALS_X86)
  static constexpr unsigned kFtz = 0x8000, kDaz = 0x0040, kFlags = 0x003f;  // MXCSR bits 0-5: sticky exception flags
  unsigned saved_ = 0;
#elif defined(PANOPTES_DENORMALS_ARM64)
  static constexpr std::uint64_t kFz = std::uint64_t(1) << 24;
  std::uint64_t saved_ = 0;
#endif
};

}  // namespace panoptes::seismic
