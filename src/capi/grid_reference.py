"""The C API's frames of a non-uniform grid, through ctypes (no Fortran, no pybind11 in between): the
reference that the Fortran module (grid_test.sh) and the Python session (src/python/tests/test_grid.py)
must match bit for bit.

    render(lib, config_text, kind, coords, snapshots, points=0, outside=0.0)

kind: "rectilinear" | "spherical" | "yinyang"; coords: three 1-D float64 arrays; snapshots: a list of
(time, [array per patch]) with arrays of shape (nz, ny, nx) (C order, x fastest), one per patch
(Yin-Yang: two). The whole grid is one block in this process; the field is named "T".
"""
import ctypes

import numpy as np

_KINDS = {"rectilinear": "panoptes_set_grid_rectilinear", "spherical": "panoptes_set_grid_spherical",
          "yinyang": "panoptes_set_grid_yinyang"}
FLOAT64 = 1


def _check(lib, rc, call):
    if rc != 0:
        raise RuntimeError(f"{call}: {lib.panoptes_last_error().decode()}")


def render(lib_path, config_text, kind, coords, snapshots, points=0, outside=0.0):
    lib = ctypes.CDLL(str(lib_path))
    lib.panoptes_last_error.restype = ctypes.c_char_p
    s = ctypes.c_void_p()
    _check(lib, lib.panoptes_create(config_text.encode(), 0, -1, ctypes.byref(s)), "panoptes_create")
    try:
        c = [np.ascontiguousarray(a, dtype=np.float64) for a in coords]
        dims = (ctypes.c_int * 3)(*[len(a) for a in c])
        ptr = [a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)) for a in c]
        _check(lib, getattr(lib, _KINDS[kind])(s, dims, *ptr), _KINDS[kind])
        _check(lib, lib.panoptes_set_resample(s, int(points), ctypes.c_double(outside)), "panoptes_set_resample")
        zero = (ctypes.c_int * 3)(0, 0, 0)
        patches = 2 if kind == "yinyang" else 1
        bound = [np.zeros((len(c[2]), len(c[1]), len(c[0])), dtype=np.float64) for _ in range(patches)]
        for p in range(patches):
            if kind == "yinyang":
                _check(lib, lib.panoptes_set_patch(s, p), "panoptes_set_patch")
            _check(lib, lib.panoptes_set_block(s, zero, dims, zero, zero), "panoptes_set_block")
            _check(lib, lib.panoptes_set_field_n(s, b"T", ctypes.c_void_p(bound[p].ctypes.data), FLOAT64, None,
                                                 ctypes.c_longlong(bound[p].size)), "panoptes_set_field_n")
        for time, arrays in snapshots:
            for p in range(patches):
                bound[p][...] = arrays[p]
            _check(lib, lib.panoptes_snapshot(s, ctypes.c_double(time)), "panoptes_snapshot")
        _check(lib, lib.panoptes_finalize(s), "panoptes_finalize")
    finally:
        lib.panoptes_destroy(s)


def compare(ref_dir, dir):
    """Largest pixel difference between two databases (0 = bitwise equal), after checking their shapes."""
    import panoptes
    ref, db = panoptes.open(ref_dir), panoptes.open(dir)
    assert ref.status == db.status == "complete", (ref.status, db.status)
    assert (ref.camera_count, ref.task_count, ref.frame_count) == (db.camera_count, db.task_count, db.frame_count)
    np.testing.assert_array_equal(ref.times, db.times)
    worst = 0
    for cam in range(ref.camera_count):
        for task in range(ref.task_count):
            for f in range(ref.frame_count):
                a, b = ref.frame(cam, task, f).astype(int), db.frame(cam, task, f).astype(int)
                worst = max(worst, int(np.abs(a - b).max()))
    return worst, ref.camera_count * ref.task_count * ref.frame_count
