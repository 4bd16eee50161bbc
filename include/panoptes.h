/* Panoptes C API: in-situ visualization of a simulation into a movie database, from C, C++ or
 * (through src/capi/panoptes.f90) Fortran. Every function returns PANOPTES_OK (0) or an error code;
 * panoptes_last_error() then describes the error (per thread). No C++ exception crosses this boundary.
 *
 * Typical use (every call is collective over the MPI communicator):
 *   panoptes_session* s;
 *   panoptes_create("viz.toml", 1, PANOPTES_COMM_WORLD, &s);    // config file (or TOML text, 0)
 *   panoptes_set_grid(s, dims, origin, spacing);                // the global grid of points
 *   panoptes_set_block(s, offset, extent, ghost_lo, ghost_hi);  // this rank's owned points + ghosts
 *   for (step...) {
 *     panoptes_set_field(s, "T", T, PANOPTES_FLOAT64, NULL);    // data = first STORED element
 *     panoptes_process(s, step, time, NULL);                    // renders when the schedule says so
 *   }
 *   panoptes_finalize(s); panoptes_destroy(s);
 * Configuration keys: docs/insitu.md ([output], [image], [rig], [schedule], [video], [render], [[task]]).
 */
#ifndef PANOPTES_H
#define PANOPTES_H

#ifdef __cplusplus
extern "C" {
#endif

/** Return codes. */
enum {
  PANOPTES_OK = 0,
  PANOPTES_ERROR_CONFIG = 1, /**< bad configuration text/file/key */
  PANOPTES_ERROR_USAGE = 2,  /**< calls in the wrong order, bad arguments, null pointers */
  PANOPTES_ERROR_RUN = 3     /**< failure while rendering or writing (disk, MPI, ...) */
};
/** Element types of fields. */
enum { PANOPTES_FLOAT32 = 0, PANOPTES_FLOAT64 = 1 };
/** Communicator argument of panoptes_create: MPI_COMM_WORLD when MPI is initialized, else one process.
 * Otherwise pass a Fortran handle: MPI_Comm_c2f(comm) in C, the communicator itself in Fortran. */
#define PANOPTES_COMM_WORLD (-1)

typedef struct panoptes_session panoptes_session;

/** Creates a session from a TOML file (config_is_file = 1) or TOML text (0). */
int panoptes_create(const char* config, int config_is_file, int fortran_comm, panoptes_session** out);
/** The global grid: dims[3] points (x, y, z), origin[3] and spacing[3] in world units. */
int panoptes_set_grid(panoptes_session* s, const int dims[3], const double origin[3], const double spacing[3]);
/** This rank's owned points (0-based global offset, extent) and the ghost layers its arrays store
 * below/above them per axis. Owned boxes of all ranks must partition the grid. */
int panoptes_set_block(panoptes_session* s, const int offset[3], const int extent[3], const int ghost_lo[3],
                       const int ghost_hi[3]);
/** (Re)binds a field for the next snapshots. data points at the first STORED element (the ghost
 * corner); strides (elements per axis) may be NULL = contiguous x-fastest over the ghosted box
 * (C array [nz][ny][nx], Fortran array (nx, ny, nz)). The data must stay valid until the next call
 * that renders. */
int panoptes_set_field(panoptes_session* s, const char* name, const void* data, int type, const long long strides[3]);
/** If the schedule asks for a snapshot at (step, time), renders and stores it; *taken (may be NULL)
 * tells whether it did. */
int panoptes_process(panoptes_session* s, long long step, double time, int* taken);
/** Renders and stores a snapshot now, whatever the schedule. */
int panoptes_snapshot(panoptes_session* s, double time);
/** Closes all movies and marks the database complete (collective). The first call prints, on rank 0 to
 * stderr, the in-situ overhead: visualization time as a multiple of the simulation time (the wall time
 * outside the library's calls since panoptes_create), per rank. */
int panoptes_finalize(panoptes_session* s);
/** Frees the session (without finalize the database is left interrupted, its snapshots playable). */
void panoptes_destroy(panoptes_session* s);
/** The message of the last error of this thread ("" if none). */
const char* panoptes_last_error(void);

#ifdef __cplusplus
}
#endif
#endif /* PANOPTES_H */
