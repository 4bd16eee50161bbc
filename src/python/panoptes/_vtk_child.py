"""The part of `panoptes.vtk_grid` that runs VTK: one .vti/.vtr/.vts file read by VTK's own XML reader in a
child process, under the memory (RLIMIT_AS) and time limits the parent sets, so that a crash, an abort or
a hang inside VTK ends this process, not the user's session. Run as a script (it does not import the
`panoptes` package):

    python3 _vtk_child.py FILE ARRAY|- OUTDIR

writes OUTDIR/values.npy (the point-data array, flat, VTK order: i fastest), OUTDIR/x.npy, y.npy, z.npy
(.vtr) or OUTDIR/points.npy ((n, 3), .vts) and OUTDIR/meta.json (dims, origin, spacing, the arrays);
a refusal is meta.json {"error": "one line"} and exit status 3."""
import json
import sys
from pathlib import Path

import numpy as np


def fail(out, message):
    (out / "meta.json").write_text(json.dumps({"error": message}))
    sys.exit(3)


def vtk_errors(window):
    """The first error VTK reported, as one line (VTK's messages span several lines and name C++ files)."""
    text = window.GetOutput() if window is not None else ""
    for line in text.splitlines():
        if "ERR" in line or "ERROR" in line or "Error" in line:
            msg = line.split(": ", 1)[-1].strip() if ": " in line else line.strip()
            return msg[:300]
    return ""


def main(argv):
    path, array, out = argv[0], (None if argv[1] == "-" else argv[1]), Path(argv[2])
    try:
        from vtkmodules import vtkCommonCore, vtkIOXML
        from vtkmodules.util import numpy_support
    except ImportError as e:
        fail(out, "reading VTK XML files needs VTK's Python modules (vtkmodules): on Debian 12 "
                  f"`apt-get install python3-paraview` ({e})")
    window = vtkCommonCore.vtkStringOutputWindow()
    vtkCommonCore.vtkOutputWindow.SetInstance(window)
    ext = Path(path).suffix.lower()
    readers = {".vti": vtkIOXML.vtkXMLImageDataReader, ".vtr": vtkIOXML.vtkXMLRectilinearGridReader,
               ".vts": vtkIOXML.vtkXMLStructuredGridReader}
    r = readers[ext]()
    r.SetFileName(path)
    r.Update()
    data = r.GetOutput()
    if data is None or data.GetNumberOfPoints() == 0:
        why = vtk_errors(window)
        fail(out, f"VTK read no points (not a valid {ext} file?{' VTK: ' + why if why else ''})")
    why = vtk_errors(window)
    if why:  # VTK reads on after some errors (a short array, a bad block); its data is then not the file's
        fail(out, f"VTK: {why}")
    dims = [0, 0, 0]
    try:
        data.GetDimensions(dims)  # vtkImageData (the no-argument form is deprecated there since VTK 9.3)
    except TypeError:
        dims = data.GetDimensions()
    dims = [int(d) for d in dims]
    if min(dims) < 2:
        fail(out, f"dimensions {dims[0]}x{dims[1]}x{dims[2]}: a volume needs at least 2 points per axis")
    pd = data.GetPointData()
    names = [pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())]
    if not names:
        cells = data.GetCellData().GetNumberOfArrays()
        fail(out, "no point-data array" + (f" ({cells} cell-data arrays: Panoptes renders values at the grid's "
                                           "points; convert them with VTK's CellDataToPointData)" if cells else ""))
    name = names[0] if array is None else array
    if name not in names:
        fail(out, f"no point-data array {name!r} (it has {', '.join(map(repr, names))})")
    a = numpy_support.vtk_to_numpy(pd.GetArray(name))
    if a.ndim != 1:
        fail(out, f"array {name!r} has {a.shape[1]} components; expected a scalar (one component)")
    if a.size != dims[0] * dims[1] * dims[2]:
        fail(out, f"array {name!r} has {a.size} values for {dims[0]}x{dims[1]}x{dims[2]} points")
    if a.dtype not in (np.float32, np.float64):
        a = a.astype(np.float64)
    np.save(out / "values.npy", a)
    meta = {"dims": dims, "array": name, "arrays": names}
    if ext == ".vti":
        if hasattr(data, "GetDirectionMatrix") and not data.GetDirectionMatrix().IsIdentity():
            fail(out, "an image with a rotated direction matrix; accepted: an axis-aligned image "
                      "(Direction=\"1 0 0 0 1 0 0 0 1\")")
        meta["origin"], meta["spacing"] = list(data.GetOrigin()), list(data.GetSpacing())
    elif ext == ".vtr":
        for n, c in zip("xyz", (data.GetXCoordinates(), data.GetYCoordinates(), data.GetZCoordinates())):
            np.save(out / f"{n}.npy", numpy_support.vtk_to_numpy(c).astype(np.float64))
    else:
        pts = numpy_support.vtk_to_numpy(data.GetPoints().GetData())
        meta["points_dtype"] = str(pts.dtype)
        np.save(out / "points.npy", pts)
    (out / "meta.json").write_text(json.dumps(meta))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
