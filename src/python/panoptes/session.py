"""In-situ visualization from a Python simulation."""
import os

from . import _panoptes


def _coordinates(*axes):
    import numpy as np
    out = []
    for a in axes:
        a = np.asarray(a, dtype=np.float64)
        if a.ndim != 1:
            raise _panoptes.Error(f"coordinate array of shape {a.shape}; expected a 1-D array")
        out.append(a.tolist())
    return out


class Session:
    """An in-situ visualization session (the C API's panoptes_session, for Python).

    config: path of a TOML file, or TOML text (anything containing a newline); keys as for
    `panoptes run` (docs/insitu.md). comm: an mpi4py communicator; without one, MPI_COMM_WORLD when
    MPI is initialized (e.g. by mpi4py), else one process. Every call is collective over comm.
    """

    def __init__(self, config, comm=None):
        config = os.fspath(config)
        is_file = "\n" not in config
        self._s = _panoptes.Session(config, is_file, comm)

    def set_grid(self, dims, origin=(0.0, 0.0, 0.0), spacing=(1.0, 1.0, 1.0)):
        """The global grid: dims = points per axis (nx, ny, nz), origin and spacing in world units."""
        self._s.set_grid([int(d) for d in dims], [float(o) for o in origin], [float(s) for s in spacing])

    def set_grid_rectilinear(self, x, y, z):
        """A rectilinear grid: 1-D arrays of strictly increasing coordinates per axis (nx, ny, nz points).
        Its fields are resampled in situ onto a uniform grid over its bounding box (set_resample)."""
        self._s.set_source_grid("rectilinear", *_coordinates(x, y, z))

    def set_grid_spherical(self, r, theta, phi):
        """A spherical shell (or sector): 1-D arrays of radii, colatitudes in [0, pi] from +z and longitudes
        (radians), each strictly increasing; point (i, j, k) = (r[i], theta[j], phi[k]), so a field's
        array has shape (nphi, ntheta, nr). Points outside the shell take the outside value (set_resample)."""
        self._s.set_source_grid("spherical", *_coordinates(r, theta, phi))

    def set_grid_yinyang(self, r, theta, phi):
        """A Yin-Yang grid: the coordinates of one patch (as set_grid_spherical), shared by Yin (patch 0)
        and Yang (patch 1, Yin's frame rotated by (x, y, z) -> (-x, z, y)). Select a block's patch with
        set_patch before its set_block and set_field."""
        self._s.set_source_grid("yinyang", *_coordinates(r, theta, phi))

    def set_patch(self, patch):
        """Yin-Yang: the patch (0 = Yin, 1 = Yang) the following set_block and set_field calls describe; a
        process may hold a block of each."""
        self._s.set_patch(int(patch))

    def set_resample(self, longest_axis_points=0, outside_value=0.0):
        """Non-uniform grids: points along the longest axis of the uniform grid the fields are resampled
        onto (0 = the source's largest dimension) and the value outside the grid's domain."""
        self._s.set_resample(int(longest_axis_points), float(outside_value))

    def set_block(self, offset, extent, ghost_lo=(0, 0, 0), ghost_hi=(0, 0, 0)):
        """This rank's owned points (0-based (x, y, z) offset, extent) and the ghost layers its arrays hold."""
        self._s.set_block([int(v) for v in offset], [int(v) for v in extent], [int(v) for v in ghost_lo],
                          [int(v) for v in ghost_hi])

    def set_halo(self, valid_lo, valid_hi, edges_valid=False):
        """Of the stored ghost layers (set_block), those the halo exchange keeps up to date per axis
        (x, y, z; -1 = every stored layer), and whether it fills edge and corner ghosts too
        (edges_valid=True: a full 26-neighbour exchange; False: face-only halos, whose edge and corner
        points Panoptes fetches from their owners). After set_block, before the first snapshot."""
        self._s.set_halo([int(v) for v in valid_lo], [int(v) for v in valid_hi], bool(edges_valid))

    def set_field(self, name, array):
        """Binds a float32/float64 array of shape (nz, ny, nx) of the block INCLUDING its ghost layers.
        The array is not copied: the session reads it at the next process()/snapshot(). Any strides
        (views, slices, as_strided) are honoured; strides whose reach overflows 64-bit offsets raise Error."""
        self._s.set_field(name, array)

    def due(self, step, time):
        """Whether the schedule asks for a snapshot at (step, time); process(step, time) would take it."""
        return self._s.due(int(step), float(time))

    def process(self, step, time):
        """Renders and stores a snapshot if the schedule asks for one; returns whether it did. A time that
        is not finite, or a snapshot time not after the previous snapshot's, raises Error (nothing written)."""
        return self._s.process(int(step), float(time))

    def snapshot(self, time):
        """Renders and stores a snapshot now, whatever the schedule (a forced snapshot). Times as process()."""
        self._s.snapshot(float(time))

    def finalize(self):
        """Closes the movies and marks the database complete."""
        self._s.finalize()

    # rank, ranks, camera_count and task_count answer as soon as the Session exists (before set_grid).
    output_dir = property(lambda self: self._s.output_dir)
    rank = property(lambda self: self._s.rank)
    ranks = property(lambda self: self._s.ranks)
    camera_count = property(lambda self: self._s.camera_count)
    task_count = property(lambda self: self._s.task_count)
    snapshots = property(lambda self: self._s.snapshots)

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            self.finalize()
        return False
