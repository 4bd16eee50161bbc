/* Panoptes C API: in-situ visualization of a simulation into a movie database, from C, C++ or
 * (through src/capi/panoptes.f90) Fortran. Every function returns PANOPTES_OK (0) or an error code;
 * panoptes_last_error() then describes the error (per thread). No C++ exception crosses this boundary.
 *
 * Typical use (every call is collective over the MPI communicator):
 *   panoptes_session* s;
 *   panoptes_create("viz.toml", 1, PANOPTES_COMM_WORLD, &s);    // config file (or TOML text, 0)
 *   panoptes_set_grid(s, dims, origin, spacing);                // the global grid of points (or
 *                                                               // _rectilinear, _spherical, _yinyang)
 *   panoptes_set_block(s, offset, extent, ghost_lo, ghost_hi);  // this rank's owned points + STORED ghosts
 *   panoptes_set_halo(s, valid_lo, valid_hi, 0);                // optional: ghosts kept up to date, face-only
 *   for (step...) {
 *     panoptes_set_field_n(s, "T", T, PANOPTES_FLOAT64, NULL, n_T); // data = first STORED element, n_T elements
 *     panoptes_process(s, step, time, NULL);                    // renders when the schedule says so
 *   }
 *   panoptes_finalize(s); panoptes_destroy(s);
 * Configuration keys: docs/insitu.md ([output] dir/mode, [image], [rig], [schedule], [video], [render],
 * [[task]]); a restarted run continues its database with [output] mode = "resume".
 * Step-by-step guide for C, C++, Fortran and Python codes: docs/instrumenting.md.
 *
 * Errors: every function returns a code; a failing call also prints "panoptes: error: ..." to stderr
 * (see panoptes_set_error_output) — the library never exits, aborts or raises a signal on a bad call.
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
/** Where failing calls print their message (panoptes_set_error_output). */
enum {
  PANOPTES_ERRORS_ALL = 0,   /**< every rank, prefixed with its rank when there are several (default) */
  PANOPTES_ERRORS_RANK0 = 1, /**< rank 0 only: once for the collective errors (configuration, grid) */
  PANOPTES_ERRORS_NONE = 2   /**< never: the caller reports panoptes_last_error() itself */
};
/** Communicator argument of panoptes_create: MPI_COMM_WORLD when MPI is initialized, else one process.
 * Otherwise pass a Fortran handle: MPI_Comm_c2f(comm) in C, the communicator itself in Fortran. */
#define PANOPTES_COMM_WORLD (-1)

typedef struct panoptes_session panoptes_session;

/** Creates a session from a TOML file (config_is_file = 1) or TOML text (0). */
int panoptes_create(const char* config, int config_is_file, int fortran_comm, panoptes_session** out);
/** The global grid: dims[3] points (x, y, z), origin[3] and spacing[3] in world units. */
int panoptes_set_grid(panoptes_session* s, const int dims[3], const double origin[3], const double spacing[3]);
/** Grids that are not uniform boxes (docs/instrumenting.md, "Grids"): the session resamples them onto a
 * uniform grid over the domain's bounding box before rendering. Arrays are indexed like a uniform grid's
 * (first axis fastest, dims[3] points, blocks and ghosts as panoptes_set_block says).
 * Rectilinear: x[dims[0]], y[dims[1]], z[dims[2]], strictly increasing coordinates. */
int panoptes_set_grid_rectilinear(panoptes_session* s, const int dims[3], const double* x, const double* y, const double* z);
/** A spherical shell (or sector): radii r[dims[0]] >= 0, colatitudes theta[dims[1]] in [0, pi] from +z and
 * longitudes phi[dims[2]] (radians), each strictly increasing; point (i, j, k) is at
 * (r sin(theta) cos(phi), r sin(theta) sin(phi), r cos(theta)). Longitudes that close the circle wrap around;
 * colatitudes within 1.5 spacings of a pole cover its cap. Points outside the shell take the outside value. */
int panoptes_set_grid_spherical(panoptes_session* s, const int dims[3], const double* r, const double* theta,
                                const double* phi);
/** A Yin-Yang grid: two patches (0 = Yin, 1 = Yang) with the coordinates of panoptes_set_grid_spherical, each
 * covering at least theta in [pi/4, 3pi/4] and phi in [-3pi/4, 3pi/4] within (0, pi) x (-pi, pi); Yang's frame is
 * Yin's rotated by (x, y, z) -> (-x, z, y). Select a rank's patch with panoptes_set_patch. */
int panoptes_set_grid_yinyang(panoptes_session* s, const int dims[3], const double* r, const double* theta,
                              const double* phi);
/** Yin-Yang: the patch (0 = Yin, 1 = Yang) that the following panoptes_set_block and panoptes_set_field* calls
 * describe. A rank may describe a block of each patch (select, set block and fields, select the other, ...).
 * After the first snapshot the blocks are fixed, but a patch that has one may be selected again to re-bind
 * its fields (a rank holding both patches: select 0, set its fields, select 1, set its fields, snapshot). */
int panoptes_set_patch(panoptes_session* s, int patch);
/** Non-uniform grids: points along the longest axis of the uniform grid the fields are resampled onto
 * (0 = the source's largest dimension, the default) and the value of points outside the grid's domain (a
 * shell's core and outside; default 0, which the absolute-value presets show transparent). */
int panoptes_set_resample(panoptes_session* s, int longest_axis_points, double outside_value);
/** This rank's owned points (0-based global offset, extent) and the ghost layers its arrays store
 * below/above them per axis. Owned boxes of all ranks must partition the grid. */
int panoptes_set_block(panoptes_session* s, const int offset[3], const int extent[3], const int ghost_lo[3],
                       const int ghost_hi[3]);
/** Of the stored ghost layers, those the caller's halo exchange keeps up to date (valid_lo/valid_hi per
 * axis, 0 ..= the stored width; NULL or -1 = every stored layer), and whether that exchange fills edge and
 * corner ghosts too (edges_valid = 1: a full 26-neighbour exchange; 0 = face-only halos, the common
 * case: Panoptes fetches edge and corner points from their owners). After panoptes_set_block, before the
 * first snapshot. */
int panoptes_set_halo(panoptes_session* s, const int valid_lo[3], const int valid_hi[3], int edges_valid);
/** (Re)binds a field for the next snapshots. data points at the first STORED element (the ghost
 * corner); strides (elements per axis x, y, z) may be NULL = contiguous x-fastest over the ghosted box
 * (C array [nz][ny][nx], Fortran array (nx, ny, nz)). No copy: the data must stay valid, at the same
 * address, until the next call that renders. Prefer panoptes_set_field_n, which checks the buffer's size. */
int panoptes_set_field(panoptes_session* s, const char* name, const void* data, int type, const long long strides[3]);
/** panoptes_set_field for a buffer of `count` elements starting at data: refused (PANOPTES_ERROR_USAGE,
 * nothing bound) when the ghosted block, at these strides, reaches outside it. */
int panoptes_set_field_n(panoptes_session* s, const char* name, const void* data, int type, const long long strides[3],
                         long long count);
/** Binds an array in any axis order: `layout` names the grid axis of each of the array's 3 dimensions, in the
 * order of extents[] and strides[] (e.g. "zxy" for a Fortran array V(k,i,j), whose first index is z;
 * "xyz" for V(i,j,k)); extents[d] = points along dimension d, which must equal the block's owned + stored
 * ghost points on that axis; strides[d] = elements between neighbours along dimension d (any sign, not 0);
 * data = the element at index 0 of every dimension. A shape that does not fit the block is refused with a
 * message naming both shapes. layout NULL or "" means "xyz" where the shape fits no other order, and is
 * refused (naming every order it fits) where it does: a ghosted cube cannot tell "xyz" from "zxy". The Fortran module passes its arrays (sections included) through this call.
 * Strides whose reach overflows 64-bit offsets are refused by every set_field call. Prefer
 * panoptes_set_field_layout_n, which also checks the buffer's size. */
int panoptes_set_field_layout(panoptes_session* s, const char* name, const void* data, int type, const char* layout,
                              const long long extents[3], const long long strides[3]);
/** panoptes_set_field_layout for a buffer of `count` elements starting at data (data = the element at index 0
 * of every dimension and the buffer's first element): refused (PANOPTES_ERROR_USAGE, nothing bound) when the
 * array, at these strides, reaches outside data[0 .. count-1] — e.g. a buffer too short for its strides, or a
 * negative stride (bind a reversed view with panoptes_set_field_layout). */
int panoptes_set_field_layout_n(panoptes_session* s, const char* name, const void* data, int type, const char* layout,
                                const long long extents[3], const long long strides[3], long long count);
/** If the schedule asks for a snapshot at (step, time), renders and stores it; *taken (may be NULL)
 * tells whether it did. A time that is not finite, or a snapshot time not after the previous snapshot's
 * (other than the times a resumed run repeats before its first new snapshot, which are skipped), is
 * refused with PANOPTES_ERROR_USAGE before anything is written. */
int panoptes_process(panoptes_session* s, long long step, double time, int* taken);
/** Whether the schedule asks for a snapshot at (step, time): *due = 1 or 0, the same on every rank. Does not
 * render; panoptes_process(step, time) would take exactly this snapshot. Collective the first time (it
 * starts the session, as the first snapshot does). */
int panoptes_due(panoptes_session* s, long long step, double time, int* due);
/** Renders and stores a snapshot now, whatever the schedule (a forced snapshot). Times as panoptes_process. */
int panoptes_snapshot(panoptes_session* s, double time);
/** Closes all movies and marks the database complete (collective). The first call prints, on rank 0 to
 * stderr, the in-situ overhead: the visualization's CPU time (all threads, inside the library's calls and
 * of its own threads) as a multiple of the rest of the process's CPU time, per rank. */
int panoptes_finalize(panoptes_session* s);
/** Frees the session (without finalize the database is left interrupted, its snapshots playable). */
void panoptes_destroy(panoptes_session* s);
/** The message of the last error of this thread ("" if none). */
const char* panoptes_last_error(void);
/** The library's version, "major.minor.patch" (static storage; never NULL). */
const char* panoptes_version(void);
/** Where failing calls print their message, process-wide: PANOPTES_ERRORS_ALL (default), _RANK0 or _NONE.
 * The environment variable PANOPTES_ERRORS=all|rank0|none sets the default before the first call. */
void panoptes_set_error_output(int mode);

#ifdef __cplusplus
}
#endif
#endif /* PANOPTES_H */
