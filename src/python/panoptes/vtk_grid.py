"""VTK XML image, rectilinear and structured grids (.vti, .vtr, .vts) as input of `panoptes render`.

The files are read by VTK's own XML readers (the `vtkmodules` package; on Debian 12 it comes with
python3-paraview, which scripts/setup installs): Panoptes does not link VTK, whose Debian package is the
whole toolkit, for three readers. What it writes is what `panoptes render` reads: the point-data array
as .npy volumes (C order (n2, n1, n0), the first axis fastest as in VTK), the coordinates as 1-D .npy
and a grid TOML for `render --grid` (docs/insitu.md):

    .vti  ImageData         uniform: no grid TOML, render's --origin and --spacing
    .vtr  RectilinearGrid   rectilinear: x, y, z as given
    .vts  StructuredGrid    explicit points, accepted when they lie on per-axis lines: rectilinear
                            (x depends on i only, y on j, z on k) or spherical ((r, theta, phi) on
                            (i, j, k)); any other curvilinear grid is refused with its reason

    /usr/bin/python3 -m panoptes.vtk_grid FILE.vtr [FILE2.vtr ...] --out DIR [--array NAME]
    -> DIR/grid.toml, DIR/<file>.npy; prints the `panoptes render` command that renders them.

Several files make a time series: they must share the grid (same kind and coordinates)."""
import argparse
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

KINDS = ("uniform", "rectilinear", "spherical")
_AXES = {"rectilinear": ("x", "y", "z"), "spherical": ("r", "theta", "phi")}


@dataclass
class VtkGrid:
    """One file's grid and values. kind: uniform | rectilinear | spherical. coordinates: three 1-D arrays
    (rectilinear: x, y, z; spherical: r, theta, phi in radians); uniform: origin and spacing instead.
    values: (n2, n1, n0) float32/float64; array: the point-data array's name."""
    path: str
    kind: str
    dims: tuple
    values: np.ndarray
    array: str
    coordinates: tuple = ()
    origin: tuple = (0.0, 0.0, 0.0)
    spacing: tuple = (1.0, 1.0, 1.0)
    notes: list = field(default_factory=list)


def _vtk():
    try:
        from vtkmodules import vtkIOXML
        from vtkmodules.util import numpy_support
    except ImportError as e:
        raise RuntimeError("reading VTK XML files needs VTK's Python modules (vtkmodules): on Debian 12 "
                           f"`apt-get install python3-paraview` ({e})") from None
    return vtkIOXML, numpy_support


def _reader(path):
    vtkIOXML, _ = _vtk()
    ext = Path(path).suffix.lower()
    readers = {".vti": vtkIOXML.vtkXMLImageDataReader, ".vtr": vtkIOXML.vtkXMLRectilinearGridReader,
               ".vts": vtkIOXML.vtkXMLStructuredGridReader}
    if ext not in readers:
        raise ValueError(f"{path}: expected a VTK XML .vti, .vtr or .vts file (a {ext or 'nameless'} file)")
    if not Path(path).is_file():
        raise FileNotFoundError(f"{path}: no such file")
    r = readers[ext]()
    r.SetFileName(str(path))
    r.Update()
    data = r.GetOutput()
    if data is None or data.GetNumberOfPoints() == 0:
        raise ValueError(f"{path}: VTK read no points (not a valid {ext} file?)")
    return data


def _point_array(path, data, name):
    _, numpy_support = _vtk()
    pd = data.GetPointData()
    names = [pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())]
    if not names:
        cells = data.GetCellData().GetNumberOfArrays()
        raise ValueError(f"{path}: no point-data array" + (f" ({cells} cell-data arrays: Panoptes renders values at "
                                                           "the grid's points; convert them with VTK's CellDataToPointData)"
                                                           if cells else ""))
    if name is None:
        name = names[0]
    elif name not in names:
        raise ValueError(f"{path}: no point-data array {name!r} (it has {', '.join(map(repr, names))})")
    a = numpy_support.vtk_to_numpy(pd.GetArray(name))
    if a.ndim != 1:
        raise ValueError(f"{path}: array {name!r} has {a.shape[1]} components; expected a scalar")
    if a.dtype not in (np.float32, np.float64):
        a = a.astype(np.float64)
    return name, a, names


def _along(values, axis, n, rtol):
    """values: (n2, n1, n0) of one coordinate; its line along `axis` if it depends on that index only."""
    line = np.moveaxis(values, axis, -1).reshape(-1, n)
    ref = line[0]
    if not np.all(np.isfinite(line)):  # e.g. theta at r = 0
        return None, float("inf")
    scale = max(float(np.abs(line).max()), 1e-30)
    worst = float(np.abs(line - ref).max()) / scale
    return ref.copy() if worst <= rtol else None, worst


def _structured_coordinates(path, points, dims, rtol=1e-6):
    """Rectilinear or spherical per-axis coordinates of a StructuredGrid's points, or ValueError."""
    n0, n1, n2 = dims
    p = points.reshape(n2, n1, n0, 3)
    # (n2, n1, n0) arrays; index axis 2 = i (fastest), 1 = j, 0 = k.
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    rect = [_along(c, ax, n, rtol) for c, ax, n in ((x, 2, n0), (y, 1, n1), (z, 0, n2))]
    if all(c is not None for c, _ in rect):
        return "rectilinear", tuple(c for c, _ in rect)
    r = np.sqrt(x * x + y * y + z * z)
    with np.errstate(invalid="ignore", divide="ignore"):
        theta = np.arccos(np.clip(z / r, -1.0, 1.0))
    phi = np.unwrap(np.arctan2(y, x), axis=0)  # along k; a full circle stays increasing
    sph = [_along(c, ax, n, rtol) for c, ax, n in ((r, 2, n0), (theta, 1, n1), (phi, 0, n2))]
    if all(c is not None for c, _ in sph):
        return "spherical", tuple(c for c, _ in sph)
    raise ValueError(
        f"{path}: a curvilinear grid: its points lie neither on per-axis lines (x along i, y along j, z along k; "
        f"worst relative deviation {max(w for _, w in rect):.2g}) nor on (r, theta, phi) lines along (i, j, k) "
        f"(worst {max(w for _, w in sph):.2g}); Panoptes renders uniform, rectilinear, spherical and Yin-Yang grids")


def read(path, array=None):
    """Reads one .vti/.vtr/.vts file: its grid (kind, coordinates or origin/spacing) and a point-data array
    (the first one unless `array` names another) as (n2, n1, n0) values."""
    path = os.fspath(path)
    data = _reader(path)
    _, numpy_support = _vtk()
    dims = [0, 0, 0]
    try:
        data.GetDimensions(dims)  # vtkImageData (the no-argument form is deprecated there since VTK 9.3)
    except TypeError:
        dims = data.GetDimensions()  # rectilinear and structured grids
    dims = tuple(int(d) for d in dims)
    if min(dims) < 2:
        raise ValueError(f"{path}: dimensions {dims[0]}x{dims[1]}x{dims[2]}: a volume needs at least 2 points per axis")
    name, a, names = _point_array(path, data, array)
    values = a.reshape(dims[2], dims[1], dims[0])
    g = VtkGrid(path, "", dims, values, name)
    if len(names) > 1 and array is None:
        g.notes.append(f"{path}: rendering point array {name!r} of {', '.join(map(repr, names))} (--array to choose)")
    ext = Path(path).suffix.lower()
    if ext == ".vti":
        if hasattr(data, "GetDirectionMatrix") and not data.GetDirectionMatrix().IsIdentity():
            raise ValueError(f"{path}: an image with a rotated direction matrix; expected axis-aligned")
        g.kind, g.origin, g.spacing = "uniform", tuple(data.GetOrigin()), tuple(data.GetSpacing())
    elif ext == ".vtr":
        g.kind = "rectilinear"
        g.coordinates = tuple(numpy_support.vtk_to_numpy(c).astype(np.float64)
                              for c in (data.GetXCoordinates(), data.GetYCoordinates(), data.GetZCoordinates()))
    else:
        pts = numpy_support.vtk_to_numpy(data.GetPoints().GetData()).astype(np.float64)
        g.kind, g.coordinates = _structured_coordinates(path, pts, dims)
    for name_, c in zip(_AXES.get(g.kind, ()), g.coordinates):
        if not np.all(np.diff(c) > 0):
            raise ValueError(f"{path}: {g.kind} coordinate {name_} is not strictly increasing "
                             f"(expected the {name_} of successive points to grow)")
    return g


def _same_grid(a, b):
    if a.kind != b.kind or a.dims != b.dims:
        return False
    if a.kind == "uniform":
        return np.allclose(a.origin, b.origin) and np.allclose(a.spacing, b.spacing)
    return all(np.array_equal(p, q) for p, q in zip(a.coordinates, b.coordinates))


def write_render_inputs(paths, out_dir, array=None, points=None):
    """Converts the files (a time series on one grid) into DIR/<stem>.npy volumes plus, for non-uniform
    grids, the coordinates and DIR/grid.toml. Returns the `panoptes render` arguments (after the
    command) that render them, without --out."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    grids = [read(p, array) for p in paths]
    if not grids:
        raise ValueError("no VTK file given")
    first = grids[0]
    for g in grids[1:]:
        if not _same_grid(first, g):
            raise ValueError(f"{g.path}: its grid differs from {first.path}'s; a time series needs one grid")
    for g in grids:
        for note in g.notes:
            print(f"vtk_grid: {note}", file=sys.stderr)
    volumes = []
    for g in grids:
        v = out / (Path(g.path).stem + ".npy")
        np.save(v, g.values)
        volumes.append(str(v))
    args = list(volumes)
    if first.kind == "uniform":
        args += ["--origin", ",".join(repr(float(o)) for o in first.origin),
                 "--spacing", ",".join(repr(float(s)) for s in first.spacing)]
    else:
        lines = ["[grid]", f'kind = "{first.kind}"']
        for name, c in zip(_AXES[first.kind], first.coordinates):
            np.save(out / f"{name}.npy", c)
            lines.append(f'{name} = "{name}.npy"')
        if points:
            lines.append(f"points = {int(points)}")
        (out / "grid.toml").write_text("\n".join(lines) + "\n")
        args += ["--grid", str(out / "grid.toml")]
    return args


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m panoptes.vtk_grid",
                                 description="Convert VTK XML .vti/.vtr/.vts files (a time series on one grid) into the "
                                             ".npy volumes and grid TOML `panoptes render` reads; prints the command.")
    ap.add_argument("files", nargs="+", help="VTK XML files, one frame each, in order")
    ap.add_argument("--out", required=True, help="directory for the .npy files and grid.toml")
    ap.add_argument("--array", help="point-data array to render (default: the first)")
    ap.add_argument("--points", type=int, help="points along the longest axis of the uniform grid rendered")
    a = ap.parse_args(argv)
    try:
        args = write_render_inputs(a.files, a.out, a.array, a.points)
    except (ValueError, OSError, RuntimeError) as e:
        print(f"vtk_grid: error: {e}", file=sys.stderr)
        return 1
    print("panoptes render " + " ".join(args) + " --out DB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
