#pragma once
// MPI for the commands that run distributed work (seismic, run, demo), whether or not they were
// started under mpirun.
#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::app {

/// Initialises MPI (thread level FUNNELED) unless the process already did, and finalises it on
/// destruction only in that case. Without MPI support it does nothing.
struct MpiScope {
  bool owned = false;
  MpiScope() {
#ifdef PANOPTES_HAVE_MPI
    int init = 0;
    MPI_Initialized(&init);
    if (!init) {
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
      owned = true;
    }
#endif
  }
  ~MpiScope() {
#ifdef PANOPTES_HAVE_MPI
    if (owned) MPI_Finalize();
#endif
  }
  MpiScope(const MpiScope&) = delete;
  MpiScope& operator=(const MpiScope&) = delete;
};

}  // namespace panoptes::app
