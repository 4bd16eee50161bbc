"""VTK XML image, rectilinear and structured grids (.vti, .vtr, .vts, a Yin-Yang .vtm) as input of `panoptes render`.

Sections: results and limits | VTK in a child process | shells: axis order, poles, seam, Yin-Yang |
reading one file, a .vtm, a series | writing render inputs | command line.

The files are read by VTK's own XML readers (the `vtkmodules` package; on Debian 12 it comes with
python3-paraview, which scripts/setup installs): Panoptes does not link VTK, whose Debian package is the
whole toolkit, for three readers. What it writes is what `panoptes render` reads: the point-data array
as .npy volumes (C order (n2, n1, n0), the first axis fastest as in VTK; shells (nphi, ntheta, nr)), the
coordinates as 1-D .npy in DIR/grid/ and a grid TOML for `render --grid` (docs/instrumenting.md):

    .vti  ImageData         uniform: no grid TOML, render's --origin and --spacing
    .vtr  RectilinearGrid   rectilinear: x, y, z as given
    .vts  StructuredGrid    explicit points, accepted when they lie on per-axis lines: rectilinear
                            (x depends on i only, y on j, z on k) or spherical ((r, theta, phi) along
                            the index axes in any order - r fastest or phi fastest - and either
                            direction; theta may reach the poles, phi may close the circle with its
                            seam plane written twice, which is dropped); a Yin-Yang code's Yang patch
                            (the same lines in Yang's frame (x, y, z) -> (-x, z, y)) pairs with the
                            Yin file beside it into one Yin-Yang frame; any other curvilinear grid is
                            refused with its deviation and what would be accepted
    .vtm  MultiBlock        two .vts blocks, Yin and Yang: one Yin-Yang frame

    /usr/bin/python3 -m panoptes.vtk_grid FILE.vtr [FILE2.vtr ...] --out DIR [--array NAME]
    -> DIR/grid.toml, DIR/grid/*.npy, DIR/<file>.npy; prints the `panoptes render` command.

Several files make a time series: they must share the grid (same kind and coordinates). Two inputs of one
name (a/run.vtr b/run.vtr) give numbered volumes (0000_run.npy, 0001_run.npy); no output replaces an input;
nothing is moved into DIR unless every file converts.

Hostile files: each file's XML header is checked first (vtk_xml_check: nesting, element count, the bytes
its extent claims against the memory limit and against the file, data block headers), and VTK then runs
in a child process (_vtk_child.py) under RLIMIT_AS (the memory limit + 1 GB) and a timeout, so that an
abort, a crash or a hang in VTK is a one-line error here."""
import argparse
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import vtk_xml_check

KINDS = ("uniform", "rectilinear", "spherical")
_AXES = {"rectilinear": ("x", "y", "z"), "spherical": ("r", "theta", "phi")}


@dataclass
# --- results and limits ---
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
    patch: object = None  # .vts shells: how the file's point order maps to (r, theta, phi)


@dataclass
class Limits:
    """What one VTK read may take. max_memory: bytes (the arrays a file claims are checked against it before
    VTK runs, and VTK's process may map it plus VTK's own ~1 GB); timeout: seconds of one VTK read."""
    max_memory: int = 0
    timeout: float = 120.0

    def memory(self):
        if self.max_memory:
            return int(self.max_memory)
        try:
            phys = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
        except (ValueError, OSError):
            phys = 8 << 30
        return min(4 << 30, phys * 3 // 4)


_CHILD = Path(__file__).with_name("_vtk_child.py")  # the script that runs VTK (tests put a crashing one here)
_VTK_OVERHEAD = 1 << 30  # address space of Python, NumPy and VTK's libraries in the child (measured: ~110 MB)


# --- VTK in a child process ---
def _child_limits(address_space, seconds):
    def apply():
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        cpu = int(seconds) + 5
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 5))
    return apply


def _run_vtk(path, array, work, limits, need):
    """Reads one file with VTK in a child process bounded in memory and time; returns its meta dict.
    A crash, an abort, running out of the memory limit or the time limit is a one-line ValueError."""
    import json
    import signal
    import subprocess
    mem = limits.memory()
    cmd = [sys.executable, str(_CHILD), str(path), array if array is not None else "-", str(work)]
    try:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                preexec_fn=_child_limits(mem + _VTK_OVERHEAD, limits.timeout),
                                start_new_session=True)
    except OSError as e:
        raise RuntimeError(f"{path}: could not start {sys.executable} to run VTK ({e})") from None
    try:
        out, err = proc.communicate(timeout=limits.timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        raise ValueError(f"{path}: VTK did not finish reading it within {limits.timeout:g} s (stopped; "
                         "--timeout SECONDS to allow more)") from None
    meta_file = Path(work) / "meta.json"
    meta = None
    if meta_file.is_file():
        try:
            meta = json.loads(meta_file.read_text())
        except ValueError:
            meta = None
    if proc.returncode == 3 and meta and "error" in meta:
        raise ValueError(f"{path}: {meta['error']}")
    text = err.decode("utf-8", "replace")
    if proc.returncode != 0 or not meta:
        if proc.returncode < 0:
            try:
                how = signal.Signals(-proc.returncode).name
            except ValueError:
                how = f"signal {-proc.returncode}"
        else:
            how = f"exit status {proc.returncode}"
        if "bad_alloc" in text or "MemoryError" in text or "Unable to allocate" in text:
            raise ValueError(f"{path}: VTK ran out of the memory limit reading it ({how}; limit "
                             f"{mem / 1e6:.0f} MB for arrays the file claims to be {need / 1e6:.3g} MB; "
                             "--max-memory MB to allow more)")
        if proc.returncode == -signal.SIGXCPU:
            raise ValueError(f"{path}: VTK used more than {limits.timeout:g} s of CPU reading it (stopped; "
                             "--timeout SECONDS to allow more)")
        last = [ln.strip() for ln in text.splitlines() if ln.strip()]
        hint = f": {last[-1][:200]}" if last else ""
        raise ValueError(f"{path}: VTK failed reading it ({how}{hint}); the file is damaged or not one VTK writes")
    return meta


@dataclass
# --- shells: axis order, poles, seam, Yin-Yang ---
class _Patch:
    """A .vts's points as a shell: which index axis carries r, theta and phi, which of them run backwards,
    and the frame they were found in ("yin": the world's, "yang": (x, y, z) -> (-x, z, y))."""
    frame: str
    axes: tuple        # index axis (0 = i, fastest) of r, theta, phi
    flips: tuple       # bool per (r, theta, phi)
    coordinates: tuple
    seam: int = 0      # duplicate phi planes dropped at the seam


_FRAMES = ("yin", "yang")
_ORDERS = ((0, 1, 2), (2, 1, 0), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1))  # r-fastest, phi-fastest first


def _line(c, axis, valid, tol_frac, angle=False):
    """c: (n2, n1, n0) values of one coordinate; the line along index `axis` if c depends on that index only
    (where valid), within tol_frac of the line's smallest spacing. Returns (line or None, deviation in cells)."""
    m = 2 - axis
    n = c.shape[m]
    rows = np.moveaxis(c, m, -1).reshape(-1, n)
    ok = np.moveaxis(valid, m, -1).reshape(-1, n).all(axis=1)
    if not ok.any():
        return None, float("inf")
    rows = rows[ok]
    if angle:
        rows = np.unwrap(rows, axis=1)
        ref0 = rows[0, 0]
        rows = rows - 2 * np.pi * np.round((rows[:, :1] - ref0) / (2 * np.pi))
    ref = rows[0].copy()
    step = np.abs(np.diff(ref))
    cell = float(step.min()) if step.size and step.min() > 0 else 0.0
    worst = float(np.abs(rows - ref).max())
    if cell == 0.0:
        return None, float("inf") if worst > 0 else 0.0
    return (ref if worst <= tol_frac * cell else None), worst / cell


def _shell(pts, tol_frac):
    """(n2, n1, n0, 3) points -> _Patch if they lie on (r, theta, phi) lines in the Yin or Yang frame, in any
    axis order, either direction; or (None, worst deviation in cells)."""
    best = float("inf")
    for frame in _FRAMES:
        x, y, z = pts[..., 0], pts[..., 1], pts[..., 2]
        if frame == "yang":
            x, y, z = -x, z, y
        rho = np.hypot(x, y)
        r = np.hypot(rho, z)
        rmax = float(r.max()) if r.size else 0.0
        if not rmax > 0 or not np.isfinite(rmax):
            return None, best
        theta = np.arctan2(rho, z)
        phi = np.arctan2(y, x)
        everywhere = np.ones(r.shape, bool)
        off_center = r > 1e-9 * rmax
        off_axis = rho > 1e-6 * rmax  # phi is undefined on the polar axis (a grid reaching the poles)
        for order in _ORDERS:
            lines = []
            for c, axis, valid, angle in ((r, order[0], everywhere, False), (theta, order[1], off_center, False),
                                          (phi, order[2], off_axis, True)):
                line, dev = _line(c, axis, valid, tol_frac, angle)
                if line is None:
                    best = min(best, dev) if np.isfinite(dev) else best
                    break
                lines.append(line)
            else:
                flips = tuple(bool(line[-1] < line[0]) for line in lines)
                lines = [line[::-1].copy() if f else line for line, f in zip(lines, flips)]
                r_, t_, p_ = lines
                t_ = np.clip(t_, 0.0, np.pi)
                p_ = p_ - 2 * np.pi * np.floor((p_[0] + np.pi) / (2 * np.pi))  # phi[0] in [-pi, pi)
                return _Patch(frame, tuple(order), flips, (r_, t_, p_)), 0.0
    return None, best


def _to_shell_values(values, patch):
    """VTK-order (n2, n1, n0) values -> (nphi, ntheta, nr) in the patch's coordinate order."""
    v = np.transpose(values, tuple(2 - a for a in reversed(patch.axes)))  # (phi, theta, r)
    for axis, f in zip((2, 1, 0), patch.flips):
        if f:
            v = np.flip(v, axis)
    if patch.seam:
        v = v[:-patch.seam]
    return v


def _close_seam(path, patch, notes):
    """A full circle written with its seam plane twice (phi[last] = phi[0] + 2 pi) or overlapping: drop the
    repeated planes; the grid is then periodic in phi."""
    r, t, p = patch.coordinates
    n = len(p)
    cell = float(np.min(np.diff(p)))
    while n > 2 and p[n - 1] - p[0] > 2 * np.pi - 1e-3 * cell and patch.seam < 2:
        n -= 1
        patch.seam += 1
    if patch.seam:
        notes.append(f"{path}: phi closes the circle; dropped {patch.seam} repeated seam plane(s) "
                     "(the grid is periodic in phi)")
        patch.coordinates = (r, t, p[:n].copy())


# --- reading one file, a .vtm, a series ---
def _structured(path, pts, dims, notes):
    """A StructuredGrid's points: ("rectilinear", coords, None) or ("spherical" | "yang", coords, _Patch)."""
    n0, n1, n2 = dims
    p = pts.reshape(n2, n1, n0, 3).astype(np.float64, copy=False)
    tol = 1e-3  # of a cell: float32 points put a shell's points ~1e-6 cells off their lines
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    ones = np.ones(x.shape, bool)
    rect = [_line(c, ax, ones, tol) for c, ax in ((x, 0), (y, 1), (z, 2))]
    if all(c is not None for c, _ in rect):
        return "rectilinear", tuple(c for c, _ in rect), None
    patch, worst = _shell(p, tol)
    if patch is None:
        rworst = max(w for _, w in rect)
        raise ValueError(
            f"{path}: a curvilinear grid Panoptes does not render: its points lie neither on x, y, z lines along "
            f"i, j, k (off by up to {rworst:.2g} cells) nor on (r, theta, phi) lines (off by {worst:.2g} cells); "
            "accepted: a rectilinear grid (x along i, y along j, z along k) or a spherical shell or sector "
            "(r, theta, phi along the three index axes in any order, either direction, poles and a closed "
            "seam included), a Yin-Yang patch, or a uniform .vti / rectilinear .vtr")
    if patch.frame == "yin":
        _close_seam(path, patch, notes)
    return ("spherical" if patch.frame == "yin" else "yang"), patch.coordinates, patch


def _read_one(path, array, limits, work):
    """One .vti/.vtr/.vts file -> VtkGrid (kind "yang" for a Yin-Yang code's Yang patch, which needs its Yin)."""

    path = os.fspath(path)
    ext = Path(path).suffix.lower()
    if ext not in (".vti", ".vtr", ".vts"):
        raise ValueError(f"{path}: expected a VTK XML .vti, .vtr or .vts file (a {ext or 'nameless'} file)"
                         if ext != ".vtm" else f"{path}: a .vtm inside a .vtm; accepted: blocks that are .vts files")
    if not Path(path).is_file():
        raise FileNotFoundError(f"{path}: no such file")
    mem = limits.memory()
    # VTK's arrays, then ours (the NumPy copies); a .vts's points are also analysed as float64 (x, y, z, r,
    # theta, phi, rho, row copies): 96 bytes a point more; a 2-million-point float64 shell measured 112 bytes a
    # point at its peak, under the 2 x 28 + 96 estimated.
    h = vtk_xml_check.scan(path, mem, copies=2, per_point=96 if ext == ".vts" else 0)
    work = Path(work)
    for f in work.glob("*"):
        f.unlink()
    meta = _run_vtk(path, array, work, limits, h.need)
    dims = tuple(int(d) for d in meta["dims"])
    values = np.load(work / "values.npy").reshape(dims[2], dims[1], dims[0])
    g = VtkGrid(path, "", dims, values, meta["array"])
    names = meta["arrays"]
    if len(names) > 1 and array is None:
        g.notes.append(f"{path}: rendering point array {g.array!r} of {', '.join(map(repr, names))} (--array to choose)")
    if ext == ".vti":
        g.kind, g.origin, g.spacing = "uniform", tuple(meta["origin"]), tuple(meta["spacing"])
        if not all(s > 0 for s in g.spacing):
            raise ValueError(f"{path}: spacing {g.spacing}; accepted: positive spacing on every axis")
    elif ext == ".vtr":
        g.kind = "rectilinear"
        g.coordinates = tuple(np.load(work / f"{n}.npy") for n in "xyz")
    else:
        pts = np.load(work / "points.npy")
        g.kind, g.coordinates, g.patch = _structured(path, pts, dims, g.notes)
        if g.patch is not None:
            g.values = _to_shell_values(values, g.patch)
            g.dims = tuple(reversed(g.values.shape))
    for name_, c in zip(_AXES.get(g.kind if g.kind != "yang" else "spherical", ()), g.coordinates):
        if not np.all(np.diff(c) > 0):
            raise ValueError(f"{path}: {g.kind} coordinate {name_} is not strictly increasing "
                             f"(accepted: {name_} growing, or falling along its whole axis, from point to point)")
    return g


def _lone_yang(path):
    return ValueError(f"{path}: the Yang patch of a Yin-Yang grid (its points lie on (r, theta, phi) lines in Yang's "
                      "frame (x, y, z) -> (-x, z, y)); accepted: its Yin patch beside it (yin.vts yang.vts, one "
                      "pair per frame) or a .vtm holding both blocks")


def _yinyang(yin, yang, label):
    """One Yin-Yang frame from its two patches (kind "spherical" in the world frame, "yang")."""
    if yin.dims != yang.dims or not all(np.allclose(a, b, rtol=1e-6, atol=1e-9)
                                        for a, b in zip(yin.coordinates, yang.coordinates)):
        raise ValueError(f"{label}: the Yin patch {yin.path} and the Yang patch {yang.path} have different "
                         "coordinates; accepted: two patches with the same r, theta, phi")
    t, p = yin.coordinates[1], yin.coordinates[2]
    if not (0 < t[0] <= np.pi / 4 + 1e-9 and 3 * np.pi / 4 - 1e-9 <= t[-1] < np.pi
            and -np.pi < p[0] <= -3 * np.pi / 4 + 1e-9 and 3 * np.pi / 4 - 1e-9 <= p[-1] < np.pi):
        raise ValueError(f"{label}: patches spanning theta [{t[0]:.4g}, {t[-1]:.4g}], phi [{p[0]:.4g}, {p[-1]:.4g}]; "
                         "accepted: Yin-Yang patches covering theta [pi/4, 3pi/4] and phi [-3pi/4, 3pi/4] "
                         "within (0, pi) x (-pi, pi)")
    g = VtkGrid(label, "yinyang", yin.dims, np.stack([yin.values, yang.values]), yin.array,
                coordinates=yin.coordinates, notes=yin.notes + yang.notes)
    return g


def _read_vtm(path, array, limits, work):

    blocks = vtk_xml_check.blocks(path)
    if len(blocks) != 2:
        raise ValueError(f"{path}: a multi-block file of {len(blocks)} data sets "
                         f"({', '.join(l or '?' for l, _ in blocks[:6])}); accepted: a Yin-Yang .vtm of two "
                         ".vts blocks, Yin and Yang, each a whole patch")
    patches = []
    for label, f in blocks:
        if Path(f).suffix.lower() != ".vts":
            raise ValueError(f"{path}: block {label or '?'} is {Path(f).name}; accepted: a Yin-Yang .vtm of two "
                             ".vts blocks")
        patches.append(_read_one(f, array, limits, work))
    kinds = sorted(g.kind for g in patches)
    if kinds != ["spherical", "yang"]:
        raise ValueError(f"{path}: its blocks are {' and '.join(g.kind for g in patches)}; accepted: a Yin block "
                         "(points on (r, theta, phi) lines) and a Yang block (the same lines in the frame "
                         "(x, y, z) -> (-x, z, y))")
    yin, yang = (patches[0], patches[1]) if patches[0].kind == "spherical" else (patches[1], patches[0])
    return _yinyang(yin, yang, path)


def _series(paths, array, limits, work):
    """Yields the frames of the inputs: one per .vti/.vtr/.vts/.vtm file, a Yin file and its Yang file
    (adjacent, either order) making one Yin-Yang frame."""
    pending = None
    for p in paths:
        p = os.fspath(p)
        g = _read_vtm(p, array, limits, work) if Path(p).suffix.lower() == ".vtm" else _read_one(p, array, limits, work)
        if pending is not None:
            a, pending = pending, None
            if g.kind == "yang" or a.kind == "yang":
                if {a.kind, g.kind} != {"spherical", "yang"}:
                    raise _lone_yang(a.path if a.kind == "yang" else g.path)
                yin, yang = (a, g) if a.kind == "spherical" else (g, a)
                yield _yinyang(yin, yang, a.path), [a.path, g.path]
                continue
            yield a, [a.path]
        pending = g
    if pending is not None:
        if pending.kind == "yang":
            raise _lone_yang(pending.path)
        yield pending, [pending.path]


def read(path, array=None, limits=None):
    """Reads one .vti/.vtr/.vts file (or a Yin-Yang .vtm): its grid (kind, coordinates or origin/spacing) and a
    point-data array (the first one unless `array` names another) as (n2, n1, n0) values; a shell's values are
    (nphi, ntheta, nr) whatever the file's point order, a Yin-Yang's (2, nphi, ntheta, nr). The file's header
    is checked first and VTK runs in a child process within `limits` (Limits())."""
    import tempfile
    limits = limits or Limits()
    with tempfile.TemporaryDirectory(prefix="panoptes-vtk-") as work:
        frames = list(_series([path], array, limits, work))
    return frames[0][0]


# --- writing render inputs ---
def _same_grid(a, b):
    if a.kind != b.kind or a.dims != b.dims:
        return False
    if a.kind == "uniform":
        return np.allclose(a.origin, b.origin) and np.allclose(a.spacing, b.spacing)
    return all(np.array_equal(p, q) for p, q in zip(a.coordinates, b.coordinates))


def _volume_names(stems):
    """One .npy name per frame: the input's stem, unless two stems would give the same name (also on a
    case-insensitive file system): then every frame is NNNN_<stem>.npy, NNNN its place in the series."""
    folded = [st.casefold() for st in stems]
    if len(set(folded)) == len(folded):
        return [f"{st}.npy" for st in stems]
    width = max(4, len(str(len(stems) - 1)))
    return [f"{k:0{width}d}_{st}.npy" for k, st in enumerate(stems)]


def _inputs(paths):
    """The real paths of every file the inputs read (a .vtm's blocks included), which no output may replace."""

    seen = set()
    for p in paths:
        seen.add(os.path.realpath(p))
        if Path(p).suffix.lower() == ".vtm":
            try:
                seen.update(os.path.realpath(f) for _, f in vtk_xml_check.blocks(p))
            except (ValueError, OSError):
                pass
    return seen


def write_render_inputs(paths, out_dir, array=None, points=None, limits=None):
    """Converts the files (a time series on one grid) into DIR/<stem>.npy volumes plus, for non-uniform
    grids, DIR/grid.toml and its coordinates in DIR/grid/. Returns the `panoptes render` arguments (after
    the command) that render them, without --out. Nothing is written into DIR unless every file converts;
    no output replaces an input, and no two frames share a name (see _volume_names)."""
    import shutil
    import tempfile
    paths = [os.fspath(p) for p in paths]
    if not paths:
        raise ValueError("no VTK file given")
    limits = limits or Limits()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".vtk_grid-", dir=out))
    try:
        work = staging / "work"
        work.mkdir()
        first, frames = None, []
        for k, (g, sources) in enumerate(_series(paths, array, limits, work)):
            if first is None:
                first = g
            elif not _same_grid(first, g):
                raise ValueError(f"{g.path}: its grid differs from {first.path}'s; a time series needs one grid")
            for note in g.notes:
                print(f"vtk_grid: {note}", file=sys.stderr)
            staged = staging / f"{k}.npy"
            np.save(staged, g.values)
            g.values = None
            frames.append((sources, staged))
        names = _volume_names([Path(src[0]).stem for src, _ in frames])
        if names[0][0].isdigit() and names[0] != f"{Path(frames[0][0][0]).stem}.npy":
            print(f"vtk_grid: {len(frames)} files share a name; the volumes are numbered in series order "
                  f"({names[0]}, ...)", file=sys.stderr)
        coords = []
        if first.kind != "uniform":
            axes = _AXES["spherical" if first.kind == "yinyang" else first.kind]
            coords = [(name, out / "grid" / f"{name}.npy", c) for name, c in zip(axes, first.coordinates)]
        targets = [out / n for n in names] + [p for _, p, _ in coords] + ([out / "grid.toml"] if coords else [])
        inputs = _inputs(paths)
        for t in targets:
            if os.path.realpath(t) in inputs:
                raise ValueError(f"{t}: an output would replace an input; choose another --out")
        volumes = []
        for (_, staged), name in zip(frames, names):
            os.replace(staged, out / name)
            volumes.append(str(out / name))
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    args = list(volumes)
    if first.kind == "uniform":
        args += ["--origin", ",".join(repr(float(o)) for o in first.origin),
                 "--spacing", ",".join(repr(float(s)) for s in first.spacing)]
    else:
        (out / "grid").mkdir(exist_ok=True)
        lines = ["[grid]", f'kind = "{first.kind}"']
        for name, path, c in coords:
            np.save(path, c)
            lines.append(f'{name} = "grid/{name}.npy"')
        if points:
            lines.append(f"points = {int(points)}")
        (out / "grid.toml").write_text("\n".join(lines) + "\n")
        args += ["--grid", str(out / "grid.toml")]
    return args


# --- command line ---
def _one_line(e):
    return str(e).replace("\r", "\\r").replace("\n", "\\n")


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="python3 -m panoptes.vtk_grid",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Convert VTK XML .vti/.vtr/.vts files (a time series on one grid) into the .npy volumes and "
                    "grid TOML `panoptes render` reads; prints the command.",
        epilog="accepted: .vti (uniform, axis-aligned), .vtr (rectilinear), .vts whose points lie on x, y, z lines\n"
               "(rectilinear) or on (r, theta, phi) lines in any axis order and direction (a spherical shell or\n"
               "sector; poles and a closed 360-degree seam included), and Yin-Yang grids: a .vtm of a Yin and a Yang\n"
               ".vts block, or a Yin .vts and its Yang .vts side by side (one frame per pair).\n"
               "outputs: DIR/<stem>.npy per frame (NNNN_<stem>.npy when two inputs share a name), DIR/grid.toml\n"
               "and DIR/grid/{x,y,z | r,theta,phi}.npy; no input is ever replaced.\n"
               "safety: each file's XML header is checked before VTK reads it (nesting <= 32, <= 100000 elements,\n"
               "the arrays an extent claims against the memory limit and the bytes the file holds, data block\n"
               "headers), and VTK runs in a child process limited to --max-memory (+1 GB for VTK itself) and\n"
               "--timeout; a crash or a hang there is a one-line error.")
    ap.add_argument("files", nargs="+", help="VTK XML files (.vti/.vtr/.vts/.vtm), one frame each, in order")
    ap.add_argument("--out", required=True, help="directory for the .npy files and grid.toml")
    ap.add_argument("--array", help="point-data array to render (default: the first)")
    ap.add_argument("--points", type=int, help="points along the longest axis of the uniform grid rendered")
    ap.add_argument("--max-memory", type=float, metavar="MB",
                    help="memory for one file's arrays (default: 3/4 of RAM, at most 4096 MB)")
    ap.add_argument("--timeout", type=float, default=120.0, metavar="SECONDS",
                    help="time for VTK to read one file (default 120)")
    a = ap.parse_args(argv)
    if a.max_memory is not None and not a.max_memory > 0:
        ap.error("--max-memory: expected a positive number of MB")
    if not a.timeout > 0:
        ap.error("--timeout: expected a positive number of seconds")
    limits = Limits(int(a.max_memory * 1e6) if a.max_memory else 0, a.timeout)
    try:
        args = write_render_inputs(a.files, a.out, a.array, a.points, limits)
    except (ValueError, OSError, RuntimeError) as e:
        print(f"vtk_grid: error: {_one_line(e)}", file=sys.stderr)
        return 1
    except Exception as e:  # noqa: BLE001 - one line, never a traceback; the fuzz test looks for these
        print(f"vtk_grid: error: internal error ({type(e).__name__}: {_one_line(e)}); please report it", file=sys.stderr)
        return 1
    print("panoptes render " + " ".join(args) + " --out DB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
