"""Issue 30: `panoptes render` is a replay through the in-situ Session, so the Python Session given the
same volumes and the [[task]] tables that render's --task shorthand stands for writes the same
manifest (task entries, axes, per-frame references) and bit-identical frames, with relative windows
on a grid above 65,536 points."""
import subprocess

import numpy as np

import panoptes
from conftest import panoptes_binary

TASKS = ["volume:hot", "iso:0.3", "iso:-0.2", "slice:z:0.5:rainbow"]


def volumes(n=48, snapshots=2):
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
    c = (n - 1) / 2
    out = []
    for t in range(snapshots):
        r1 = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
        r2 = np.sqrt((x - c - 6) ** 2 + (y - c + 5) ** 2 + (z - c - 3) ** 2)
        v = np.exp(-((r1 - 8 - 5 * t) / 3) ** 2) - 0.7 * np.exp(-((r2 - 5 - 3 * t) / 2.5) ** 2)
        out.append(np.ascontiguousarray(v, dtype=np.float32))
    return out


def test_render_equals_python_session_with_relative_windows(tmp_path):
    binary = panoptes_binary()
    vols = volumes()
    files = []
    for i, v in enumerate(vols):
        files.append(str(tmp_path / f"v_{i}.npy"))
        np.save(files[-1], v)
    args = [binary, "render", *files, "--rig", "fibonacci:3", "--size", "40x32", "-q", "--out", str(tmp_path / "cli")]
    for t in TASKS:
        args += ["--task", t]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    # The tables render's shorthand stands for, as render prints them.
    tables = subprocess.run([binary, "render", "--print-tasks"] + sum((["--task", t] for t in TASKS), []),
                            check=True, capture_output=True, text=True).stdout
    toml = (f'[output]\ndir = "{tmp_path / "py"}"\n[image]\nwidth = 40\nheight = 32\n[rig]\nspec = "fibonacci:3"\n'
            'up_axis = "z_up"\n[schedule]\nevery_steps = 1\n[render]\nadaptive = true\n' + tables)
    s = panoptes.Session(toml)
    s.set_grid(vols[0].shape[::-1])
    s.set_block((0, 0, 0), vols[0].shape[::-1])
    for i, v in enumerate(vols):
        s.set_field("volume", v)
        s.snapshot(float(i))
    s.finalize()

    a = panoptes.open(tmp_path / "py")
    b = panoptes.open(tmp_path / "cli")
    ma, mb = a.manifest, b.manifest
    assert ma["tasks"] == mb["tasks"] and len(ma["tasks"]) == 4
    assert ma.get("axes") == mb.get("axes") and ma.get("axes")
    assert ma["fields"] == mb["fields"]
    refs = ma["fields"][0]["references"]
    assert len(refs) == 2 and refs[0] != refs[1]
    for c in range(a.camera_count):
        for t in range(a.task_count):
            for f in range(2):
                fa, fb = a.frame(c, t, f), b.frame(c, t, f)
                assert np.array_equal(fa, fb), (c, t, f)
