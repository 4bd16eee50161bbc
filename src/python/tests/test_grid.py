"""panoptes.Session with grids that are not uniform boxes (issue 33): the frames equal the C API's
(ctypes, src/capi/grid_reference.py) bit for bit for the same coordinates and values; bad coordinates,
patches and shapes are refused with their reason."""
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import panoptes

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "capi"))
import grid_reference  # noqa: E402

TOML = """
[output]
dir = "{dir}"
[image]
width = 40
height = 32
[rig]
spec = "fibonacci:3"
[schedule]
every_steps = 1
[[task]]
name = "T"
type = "volume"
field = "T"
preset = "diverging"
relative = false
window = [-1.0, 1.0]
"""


def capi_lib():
    path = os.environ.get("PANOPTES_CAPI_LIB")
    if not path:
        pytest.skip("PANOPTES_CAPI_LIB not set (ctest sets it)")
    return path


def shell_field(r, theta, phi, t, yang=False):
    """World-position field on a (phi, theta, r) mesh: a radial profile times drifting harmonics."""
    P, T, R = np.meshgrid(phi, theta, r, indexing="ij")
    a, b, c = R * np.sin(T) * np.cos(P), R * np.sin(T) * np.sin(P), R * np.cos(T)
    x, y, z = (-a, c, b) if yang else (a, b, c)
    return np.sin(np.pi * (R - r[0]) / (r[-1] - r[0])) * (
        0.5 + 0.4 * (3 * z * z / (R * R) - 1) + 0.6 * ((x * x - y * y) * np.cos(2 * t) + 2 * x * y * np.sin(2 * t)) / (R * R))


def yinyang_coordinates(nr=6, nth=16, nph=36):
    dt, dp = (np.pi / 2) / (nth - 5), 1.5 * np.pi / (nph - 5)
    return (np.linspace(0.35, 1.0, nr), np.pi / 4 - 2 * dt + dt * np.arange(nth),
            -0.75 * np.pi - 2 * dp + dp * np.arange(nph))


def test_spherical_shell_equals_the_c_api(tmp_path):
    lib = capi_lib()
    r, theta, phi = np.linspace(0.35, 1.0, 8), np.linspace(0.02, np.pi - 0.02, 20), np.linspace(-np.pi, np.pi, 41)[:-1]
    times = [0.0, 0.6]
    fields = [shell_field(r, theta, phi, t) for t in times]
    s = panoptes.Session(TOML.format(dir=tmp_path / "py"))
    s.set_grid_spherical(r, theta, phi)
    s.set_resample(36, 0.0)
    s.set_block((0, 0, 0), (len(r), len(theta), len(phi)))
    T = np.zeros((len(phi), len(theta), len(r)), dtype=np.float32)
    s.set_field("T", T)
    for t, f in zip(times, fields):
        T[...] = f  # in place: the session reads the bound array at each snapshot
        s.snapshot(t)
    s.finalize()
    cwd = os.getcwd()
    grid_reference.render(lib, TOML.format(dir=tmp_path / "c"), "spherical", (r, theta, phi),
                          [(t, [f.astype(np.float32)]) for t, f in zip(times, fields)], points=36)
    assert os.getcwd() == cwd
    worst, frames = grid_reference.compare(tmp_path / "c", tmp_path / "py")
    assert frames == 3 * 1 * 2 and worst == 0
    db = panoptes.open(tmp_path / "py")
    assert db.frame(0, 0, 1).max() > 40  # the shell is visible
    assert np.abs(db.frame(0, 0, 0).astype(int) - db.frame(0, 0, 1).astype(int)).max() > 10  # and it moved


def test_yinyang_both_patches_in_one_process_equals_the_c_api(tmp_path):
    lib = capi_lib()
    r, theta, phi = yinyang_coordinates()
    fields = [shell_field(r, theta, phi, 0.3, yang=p == 1) for p in (0, 1)]
    s = panoptes.Session(TOML.format(dir=tmp_path / "py"))
    s.set_grid_yinyang(r, theta, phi)
    s.set_resample(40)
    for p in (0, 1):
        s.set_patch(p)
        s.set_block((0, 0, 0), (len(r), len(theta), len(phi)))
        s.set_field("T", fields[p])
    s.snapshot(0.3)
    s.finalize()
    grid_reference.render(lib, TOML.format(dir=tmp_path / "c"), "yinyang", (r, theta, phi), [(0.3, fields)], points=40)
    worst, _ = grid_reference.compare(tmp_path / "c", tmp_path / "py")
    assert worst == 0
    assert "yinyang 6x16x36" in (tmp_path / "py" / "panoptes.json").read_text()


def test_yinyang_one_process_rebinds_both_patches_every_step(tmp_path):
    """Issue 42, point 7: a process holding both patches binds each patch's new arrays every step.
    set_patch was refused after the first snapshot and Yin kept rendering step 0's array."""
    lib = capi_lib()
    r, theta, phi = yinyang_coordinates()
    steps = [(t, [shell_field(r, theta, phi, t, yang=p == 1) for p in (0, 1)]) for t in (0.3, 0.6)]
    s = panoptes.Session(TOML.format(dir=tmp_path / "py"))
    s.set_grid_yinyang(r, theta, phi)
    s.set_resample(40)
    for i, (t, fields) in enumerate(steps):
        for p in (0, 1):
            s.set_patch(p)
            if i == 0:
                s.set_block((0, 0, 0), (len(r), len(theta), len(phi)))
            s.set_field("T", fields[p])  # a new array of this step
        s.snapshot(t)
    with pytest.raises(panoptes.Error, match="cannot change"):
        s.set_block((0, 0, 0), (len(r), len(theta), len(phi)))
    s.finalize()
    grid_reference.render(lib, TOML.format(dir=tmp_path / "c"), "yinyang", (r, theta, phi), steps, points=40)
    worst, _ = grid_reference.compare(tmp_path / "c", tmp_path / "py")
    assert worst == 0


def test_rectilinear_equals_the_c_api(tmp_path):
    lib = capi_lib()
    x = np.cumsum(np.linspace(0.5, 1.5, 20)) - 7
    y, z = np.linspace(-5, 5, 16), np.geomspace(1, 11, 14) - 6
    Z, Y, X = np.meshgrid(z, y, x, indexing="ij")
    f = np.exp(-(X ** 2 + Y ** 2 + Z ** 2) / 12.0) - 0.3
    s = panoptes.Session(TOML.format(dir=tmp_path / "py"))
    s.set_grid_rectilinear(x, y, z)
    s.set_block((0, 0, 0), (20, 16, 14))
    s.set_field("T", f)
    s.snapshot(0.0)
    s.finalize()
    grid_reference.render(lib, TOML.format(dir=tmp_path / "c"), "rectilinear", (x, y, z), [(0.0, [f])])
    assert grid_reference.compare(tmp_path / "c", tmp_path / "py")[0] == 0


def test_grid_errors(tmp_path):
    r, theta, phi = yinyang_coordinates()
    s = panoptes.Session(TOML.format(dir=tmp_path / "x"))
    bad = r.copy()
    bad[3] = bad[2]
    with pytest.raises(panoptes.Error, match=r"set_grid_spherical: spherical grid: r coordinates are not strictly increasing"):
        s.set_grid_spherical(bad, theta, phi)
    with pytest.raises(panoptes.Error, match="leave a gap"):
        s.set_grid_yinyang(r, theta[3:-3], phi)
    with pytest.raises(panoptes.Error, match=r"expected a 1-D array"):
        s.set_grid_rectilinear(np.zeros((2, 3)), theta, phi)
    with pytest.raises(panoptes.Error, match="expected 2 to 65535 points"):
        s.set_grid_rectilinear([1.0], theta, phi)
    s.set_grid_spherical(r, theta, phi)
    with pytest.raises(panoptes.Error, match="only a Yin-Yang grid has patches"):
        s.set_patch(1)
    with pytest.raises(panoptes.Error, match="expected 2 to 4096"):
        s.set_resample(1)
    # A Yin-Yang grid with only Yin described: the Yang patch is missing.
    s.set_grid_yinyang(r, theta, phi)
    with pytest.raises(panoptes.Error, match=r"patch 2; expected 0 \(Yin\) or 1 \(Yang\)"):
        s.set_patch(2)
    s.set_block((0, 0, 0), (len(r), len(theta), len(phi)))
    s.set_field("T", np.zeros((len(phi), len(theta), len(r)), dtype=np.float32))
    with pytest.raises(panoptes.Error, match="a block is missing"):
        s.snapshot(0.0)
