"""VTK XML grids into `panoptes render` (issue 33): files written by VTK's own writers (.vti, .vtr, .vts)
convert to the volumes, coordinates and grid TOML render reads, and render the same frames as the same
values given as .npy directly; curvilinear and malformed input is refused with its reason."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import panoptes
from panoptes import vtk_grid

vtk = pytest.importorskip("vtkmodules.vtkCommonDataModel", reason="VTK's Python modules (python3-paraview)")
from vtkmodules import vtkCommonCore, vtkIOXML  # noqa: E402
from vtkmodules.util import numpy_support  # noqa: E402

RENDER = ["--rig", "fibonacci:3", "--task", "volume:diverging:-1:1", "--size", "40x32", "-q"]


def binary():
    path = os.environ.get("PANOPTES_BINARY")
    if not path:
        pytest.skip("PANOPTES_BINARY not set (ctest sets it)")
    return path


def render(args, out):
    subprocess.run([binary(), "render", *args, *RENDER, "--out", str(out)], check=True)
    return panoptes.open(out)


def same_frames(a, b):
    worst = 0
    for c in range(a.camera_count):
        for f in range(a.frame_count):
            worst = max(worst, int(np.abs(a.frame(c, 0, f).astype(int) - b.frame(c, 0, f).astype(int)).max()))
    return worst


def point_data(grid, values, name="T"):
    arr = numpy_support.numpy_to_vtk(np.ascontiguousarray(values).ravel(), deep=True)
    arr.SetName(name)
    grid.GetPointData().AddArray(arr)


def write(writer, grid, path):
    w = writer()
    w.SetFileName(str(path))
    w.SetInputData(grid)
    assert w.Write() == 1
    return path


def blob(X, Y, Z, t=0.0):
    return (np.exp(-((X - 2 * t) ** 2 + Y ** 2 + Z ** 2) / 10.0) * 1.6 - 0.6).astype(np.float32)


def rectilinear(tmp_path, t):
    x = np.cumsum(np.linspace(0.5, 1.5, 16)) - 8
    y, z = np.linspace(-5, 5, 12), np.geomspace(1, 11, 10) - 6
    g = vtk.vtkRectilinearGrid()
    g.SetDimensions(len(x), len(y), len(z))
    for setter, c in ((g.SetXCoordinates, x), (g.SetYCoordinates, y), (g.SetZCoordinates, z)):
        setter(numpy_support.numpy_to_vtk(c, deep=True))
    Z, Y, X = np.meshgrid(z, y, x, indexing="ij")
    point_data(g, blob(X, Y, Z, t))
    return (x, y, z), blob(X, Y, Z, t), write(vtkIOXML.vtkXMLRectilinearGridWriter, g, tmp_path / f"box_{t}.vtr")


def test_rectilinear_series_renders_as_its_npy(tmp_path):
    series = [rectilinear(tmp_path, t) for t in (0.0, 1.0)]
    coords = series[0][0]
    args = vtk_grid.write_render_inputs([f for _, _, f in series], tmp_path / "conv")
    assert (tmp_path / "conv" / "grid.toml").read_text().startswith('[grid]\nkind = "rectilinear"')
    for name, c in zip("xyz", coords):
        assert np.array_equal(np.load(tmp_path / "conv" / "grid" / f"{name}.npy"), c)
    via_vtk = render(args, tmp_path / "vtk_db")
    # The same values and coordinates as .npy written here, without VTK: the same frames.
    direct = tmp_path / "direct"
    direct.mkdir()
    for name, c in zip("xyz", coords):
        np.save(direct / f"{name}.npy", c)
    (direct / "grid.toml").write_text('[grid]\nkind = "rectilinear"\nx = "x.npy"\ny = "y.npy"\nz = "z.npy"\n')
    volumes = []
    for k, (_, values, _) in enumerate(series):
        volumes.append(str(direct / f"v{k}.npy"))
        np.save(volumes[-1], values)
    ref = render([*volumes, "--grid", str(direct / "grid.toml")], tmp_path / "ref_db")
    assert via_vtk.frame_count == 2 and same_frames(via_vtk, ref) == 0
    assert via_vtk.frame(0, 0, 1).max() > 40  # the blob is visible


def test_structured_grid_on_spherical_lines_is_a_shell(tmp_path):
    r, theta, phi = np.linspace(0.4, 1.0, 7), np.linspace(0.1, np.pi - 0.1, 14), np.linspace(-np.pi, np.pi, 31)[:-1]
    P, T, R = np.meshgrid(phi, theta, r, indexing="ij")
    pts = np.stack([R * np.sin(T) * np.cos(P), R * np.sin(T) * np.sin(P), R * np.cos(T)], axis=-1)
    g = vtk.vtkStructuredGrid()
    g.SetDimensions(len(r), len(theta), len(phi))
    p = vtkCommonCore.vtkPoints()
    p.SetData(numpy_support.numpy_to_vtk(pts.reshape(-1, 3), deep=True))
    g.SetPoints(p)
    point_data(g, np.sin(np.pi * (R - 0.4) / 0.6) * np.cos(2 * P) * np.sin(T))
    point_data(g, R, "radius")
    path = write(vtkIOXML.vtkXMLStructuredGridWriter, g, tmp_path / "shell.vts")
    grid = vtk_grid.read(path)
    assert grid.kind == "spherical" and grid.array == "T" and grid.notes  # two arrays: says which it renders
    for got, want in zip(grid.coordinates, (r, theta, phi)):
        assert np.allclose(got, want, atol=1e-12)
    assert np.array_equal(vtk_grid.read(path, array="radius").values, R)
    db = render(vtk_grid.write_render_inputs([path], tmp_path / "conv", points=32), tmp_path / "db")
    assert '"grid":"spherical 7x14x30' in (tmp_path / "db" / "panoptes.json").read_text()
    assert db.frame(0, 0, 0).max() > 40


def test_image_data_is_uniform(tmp_path):
    g = vtk.vtkImageData()
    g.SetDimensions(12, 10, 8)
    g.SetOrigin(-1.0, 2.0, 0.5)
    g.SetSpacing(0.5, 0.25, 1.0)
    z, y, x = np.mgrid[0:8, 0:10, 0:12]
    point_data(g, blob(0.5 * x - 3, 0.25 * y - 1.2, z - 3.5))
    args = vtk_grid.write_render_inputs([write(vtkIOXML.vtkXMLImageDataWriter, g, tmp_path / "u.vti")], tmp_path / "conv")
    assert args[1:] == ["--origin", "-1.0,2.0,0.5", "--spacing", "0.5,0.25,1.0"]
    db = render(args, tmp_path / "db")
    assert db.frame(0, 0, 0).max() > 40


def test_refusals(tmp_path):
    # Curvilinear: a sheared box is neither rectilinear nor spherical.
    z, y, x = np.mgrid[0:6, 0:5, 0:4].astype(np.float64)
    pts = np.stack([x + 0.3 * y, y, z], axis=-1)
    g = vtk.vtkStructuredGrid()
    g.SetDimensions(4, 5, 6)
    p = vtkCommonCore.vtkPoints()
    p.SetData(numpy_support.numpy_to_vtk(pts.reshape(-1, 3), deep=True))
    g.SetPoints(p)
    point_data(g, x)
    sheared = write(vtkIOXML.vtkXMLStructuredGridWriter, g, tmp_path / "sheared.vts")
    with pytest.raises(ValueError, match=r"sheared.vts: a curvilinear grid"):
        vtk_grid.read(sheared)
    with pytest.raises(ValueError, match=r"no point-data array 'rho' \(it has 'T'\)"):
        vtk_grid.read(sheared, array="rho")
    with pytest.raises(ValueError, match=r"expected a VTK XML .vti, .vtr or .vts file"):
        vtk_grid.read(tmp_path / "x.vtk")
    # Decreasing x coordinates.
    rg = vtk.vtkRectilinearGrid()
    rg.SetDimensions(3, 2, 2)
    for setter, c in ((rg.SetXCoordinates, [2.0, 1.0, 0.0]), (rg.SetYCoordinates, [0.0, 1.0]), (rg.SetZCoordinates, [0.0, 1.0])):
        setter(numpy_support.numpy_to_vtk(np.array(c), deep=True))
    point_data(rg, np.zeros(12))
    bad = write(vtkIOXML.vtkXMLRectilinearGridWriter, rg, tmp_path / "bad.vtr")
    with pytest.raises(ValueError, match=r"bad.vtr: rectilinear coordinate x is not strictly increasing"):
        vtk_grid.read(bad)
    # The command line: one clear line and a non-zero exit.
    run = subprocess.run([sys.executable, "-m", "panoptes.vtk_grid", str(sheared), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True)
    assert run.returncode == 1 and run.stderr.startswith("vtk_grid: error: ") and run.stderr.count("\n") == 1
