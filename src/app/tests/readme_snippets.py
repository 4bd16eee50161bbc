"""Runs every shell and Python snippet of README.md (helper of cli.readme, readme.sh).

Usage: readme_snippets.py README.md PANOPTES_BINARY WORKDIR

Shell blocks (```sh) run command by command (a trailing backslash joins lines, '#' starts a comment),
Python blocks (```python) as one script each, in WORKDIR where `panoptes` is on PATH and these stand-ins
exist (README's commands name them):
  out/demo      the demo itself (`panoptes demo`'s configuration: Yin-Yang cameras x the same 3 tasks x 40
                snapshots) on a smaller grid, with 16 cameras of 48x40 pictures so it takes seconds
  path.txt      a script of timed commands as README describes it
  paraview.cdb  a Cinema Spec D database (exported from the small demo)
  snap_*.npy    a small volume
  viz.toml      an in-situ configuration for the Python Session, whose variables (nx, ny, nz, origin,
                spacing, offset, extent, ghost_lo, ghost_hi, T, step, time) PYTHON_PRELUDE defines
  examples/     the repository's examples, but for examples/seismic/paper_reduced.toml: the same run on a
                grid of half the resolution (32x64x20, h = 800 m) for 100 steps with 2 snapshots, so the
                README's seismic -> render chain runs in seconds
CHECKS runs a check after some commands: the seismic chain's database must be oriented by the snapshots'
sidecars (z is depth: up axis z_down, units m, s, 1/s) and its side view must show the free surface on
top (issue 41).
SKIPPED lists the few commands that cannot run here, each with the reason; a skipped command that is no
longer in README fails the test, so the list stays true. Prints one line per command; exits 1 on the
first failure with its output.
"""
import os
import re
import shutil
import subprocess
import sys
import time

# Commands that legitimately cannot run in a test, with why (and what tests them instead).
SKIPPED = {
    "scripts/demo": "builds and runs the full 2.6-min demo, then opens a window (scripts/firstcontact times it)",
    "scripts/test": "the test suite itself",
    "cmake -S . -B build -DCMAKE_INSTALL_PREFIX=$HOME/opt/panoptes && cmake --build build && cmake --install build":
        "a full build and install (capi.install installs into a temporary prefix and builds against it)",
    "panoptes demo --out out/demo": "the full demo takes minutes (cli.demo runs it shortened; out/demo here is the small demo)",
    "mpirun -np 4 panoptes run my.toml --out out/run": "the full demo configuration on 4 ranks: minutes (cli.run, insitu MPI tests)",
    "panoptes run examples/paper.toml": "the paper's full run: ~28 min on 2 cores (docs/rendering.md)",
    "mpirun -np 4 panoptes seismic examples/seismic/paper_reduced.toml": "the same on 4 MPI ranks (cli.seismic, seismic MPI tests)",
    "panoptes play out/demo": "an interactive window that runs until closed (the ui.window tests run it under xvfb)",
    "panoptes serve out/demo": "a server that runs until Ctrl+C, on the fixed port 8080 (cli.serve and web.browser use free ports)",
    "panoptes serve out/demo --bind 0.0.0.0 --port 9000 --token s3cret":
        "a server on all interfaces that runs until Ctrl+C (cli.serve tests --bind and --token)",
}

PYTHON_PRELUDE = """
import numpy as np
nx, ny, nz = 16, 12, 8
origin, spacing = (0.0, 0.0, 0.0), (1.0, 1.0, 1.0)
offset, extent, ghost_lo, ghost_hi = (0, 0, 0), (nx, ny, nz), (0, 0, 0), (0, 0, 0)
T = np.fromfunction(lambda k, j, i: np.sin(i / 3.0) * np.cos(j / 4.0) + k / nz, (nz, ny, nx)).astype(np.float32)
step, time = 0, 0.0
"""

VIZ_TOML = """
[output]
dir = "viz_out"
overwrite = true
[image]
width = 48
height = 40
[rig]
spec = "fibonacci:4"
[schedule]
every_steps = 1
[[task]]
name = "temperature"
type = "volume"
field = "T"
preset = "hot"
"""

# examples/seismic/paper_reduced.toml, shortened: (line of the real file, its stand-in).
PAPER_REDUCED_SHORTER = [("nx = 64", "nx = 32"), ("ny = 128", "ny = 64"), ("nz = 40", "nz = 20"), ("h = 400.0", "h = 800.0"),
                         ("steps = 600", "steps = 100"), ("pml_cells = 10", "pml_cells = 5"),
                         ("snapshot_every = 200", "snapshot_every = 50")]

PATH_TXT = "t=0.5 key=Right\nt=1.0 key=Tab\nt=1.2 seek=10\nt=3.0 snap=0,0,1\n"


def snippets(readme):
    """(language, first line number, text) of every ```sh and ```python block."""
    blocks, lang, start, lines = [], None, 0, []
    for number, line in enumerate(open(readme, encoding="utf-8"), 1):
        fence = re.match(r"^```(\w*)\s*$", line)
        if fence and lang is None:
            lang, start, lines = fence.group(1), number + 1, []
        elif fence:
            if lang in ("sh", "python"):
                blocks.append((lang, start, "".join(lines)))
            lang = None
        elif lang is not None:
            lines.append(line)
    return blocks


def shell_commands(text, first_line):
    """(line number, command) of a shell block: comments removed, continuation lines joined."""
    out, pending, pending_line = [], "", 0
    for offset, raw in enumerate(text.splitlines()):
        line = re.sub(r"(^|\s)#.*$", "", raw).rstrip()
        if not pending:
            pending_line = first_line + offset
        if line.endswith("\\"):
            pending += line[:-1].rstrip() + " "
            continue
        command = (pending + line).strip()
        pending = ""
        if command:
            out.append((pending_line, re.sub(r"\s+", " ", command)))
    return out


def run(args, cwd, env, what, timeout=280):
    started = time.monotonic()
    r = subprocess.run(args, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=timeout)
    if r.returncode != 0:
        print(f"FAIL: {what} exited with {r.returncode}:\n{r.stdout[-3000:]}")
        sys.exit(1)
    return time.monotonic() - started


def prepare(work, panoptes, repo, env):
    os.makedirs(os.path.join(work, "bin"))
    os.symlink(panoptes, os.path.join(work, "bin", "panoptes"))
    os.makedirs(os.path.join(work, "examples", "seismic"))
    for name in os.listdir(os.path.join(repo, "examples")):
        if name != "seismic":
            os.symlink(os.path.join(repo, "examples", name), os.path.join(work, "examples", name))
    with open(os.path.join(repo, "examples", "seismic", "paper_reduced.toml")) as f:
        paper_reduced = f.read()
    for old, new in PAPER_REDUCED_SHORTER:
        paper_reduced, n = re.subn("^" + re.escape(old) + r"(?=\s|$)", new, paper_reduced, flags=re.M)
        if n != 1:
            print(f"FAIL: examples/seismic/paper_reduced.toml has no line '{old}' (update readme_snippets.py)")
            sys.exit(1)
    with open(os.path.join(work, "examples", "seismic", "paper_reduced.toml"), "w") as f:
        f.write(paper_reduced)
    config = subprocess.run([panoptes, "demo", "--print-config"], stdout=subprocess.PIPE, text=True, check=True).stdout
    small = config
    for old, new in [("nx = 64", "nx = 24"), ("ny = 128", "ny = 48"), ("nz = 40", "nz = 16"), ("h = 400.0", "h = 1066.6667"),
                     ("pml_cells = 10", "pml_cells = 4"), ("width = 528", "width = 48"), ("height = 512", "height = 40"),
                     ('spec = "yinyang"', 'spec = "yinyang:2x4"')]:
        small, n = re.subn("^" + re.escape(old) + r"(?=\s|$)", new, small, flags=re.M)
        if n != 1:
            print(f"FAIL: the demo configuration has no line '{old}' (update readme_snippets.py)")
            sys.exit(1)
    with open(os.path.join(work, "small_demo.toml"), "w") as f:
        f.write(small)
    seconds = run(["panoptes", "run", "small_demo.toml", "--out", "out/demo", "-q"], work, env, "the small demo")
    print(f"prepared out/demo (the demo's configuration on a 24x48x16 grid, 16 cameras, 48x40 pictures) in {seconds:.1f} s")
    run(["panoptes", "export-cinema", "out/demo", "paraview.cdb", "--frames", "0,39"], work, env, "paraview.cdb")
    import numpy as np
    for i in range(1):
        z, y, x = np.mgrid[0:12, 0:16, 0:20].astype(np.float32)
        np.save(os.path.join(work, f"snap_{i:03d}.npy"), np.sin(x / (3 + i)) * np.cos(y / 4) * (z / 12))
    with open(os.path.join(work, "viz.toml"), "w") as f:
        f.write(VIZ_TOML)
    with open(os.path.join(work, "path.txt"), "w") as f:
        f.write(PATH_TXT)


def check_seismic_chain(work, db_dir="out/seismic.db", snapshots="out/seismic/snapshots"):
    """The README's seismic -> render chain (issue 41): the database is oriented and labelled by the snapshots'
    sidecars, and a side view shows the free surface (z = 0) in the upper half of the picture.

    The solver's z is depth. Before the sidecars `render` took z as up: the free surface was drawn at the
    bottom of every picture (nothing warned). In a side view (the camera nearest the horizon) the wave field
    of a source in the upper half of the domain, trapped and amplified in the slow sediment layer under the
    free surface, is brighter above the picture's middle (the domain's centre, which the cameras look at)
    than below it. Checked on the last frame: the colour (max - min of R, G, B: the field, not the grey outline
    box) above the middle row must exceed twice the colour below it. Measured (2026-11-29): 3.9 with the
    surface on top, 0.25 with the binary before issue 41 (z taken as up); 3.9-4.1 and 0.25 on four more side
    views. Returns a line for the log."""
    import json
    import numpy as np
    import panoptes
    with open(os.path.join(work, db_dir, "panoptes.json")) as f:
        manifest = json.load(f)
    sidecar_files = sorted(n for n in os.listdir(os.path.join(work, snapshots)) if n.startswith("phi_p_") and n.endswith(".json"))
    sidecars = [json.load(open(os.path.join(work, snapshots, n))) for n in sidecar_files]
    problems = []
    domain = manifest.get("domain", {})
    if domain.get("up_axis") != "z_down":
        problems.append(f"domain.up_axis is {domain.get('up_axis')!r}, expected 'z_down' (the snapshots' z is depth)")
    if domain.get("units") != "m":
        problems.append(f"domain.units is {domain.get('units')!r}, expected 'm'")
    if manifest.get("time_units") != "s":
        problems.append(f"time_units is {manifest.get('time_units')!r}, expected 's'")
    fields = [(x.get("name"), x.get("units")) for x in manifest.get("fields", [])]
    if fields != [("phi_p", "1/s")]:
        problems.append(f"fields are {fields}, expected [('phi_p', '1/s')]")
    if not sidecars or manifest.get("times") != [s.get("time") for s in sidecars]:
        problems.append(f"times {manifest.get('times')} are not the sidecars' {[s.get('time') for s in sidecars]}")
    db = panoptes.open(os.path.join(work, db_dir))
    side = int(np.argmin(np.abs(db.cameras.latitude)))
    img = db.frame(camera=side, task=0, frame=db.frame_count - 1).astype(np.float64)
    colour = img.max(axis=2) - img.min(axis=2)  # the field's orange; the grey outline box (symmetric) counts 0
    h = colour.shape[0]
    above, below = colour[: h // 2].sum(), colour[h - h // 2:].sum()
    if not above > 2 * below:
        problems.append(f"camera {side} (latitude {db.cameras.latitude[side]:.1f} deg, the side view) shows less colour above "
                        f"its middle row than twice below it ({above:.0f} vs {below:.0f}): the free surface is not on top")
    if problems:
        print("FAIL: the seismic -> render chain:\n  " + "\n  ".join(problems))
        sys.exit(1)
    return (f"check the seismic chain: up_axis z_down, units m, s, 1/s; side camera {side} "
            f"(latitude {db.cameras.latitude[side]:.1f} deg): colour above / below the middle {above / max(below, 1):.2f}")


# Checks run after a README command (the command's exact text), with what they check.
CHECKS = {
    "panoptes render 'out/seismic/snapshots/phi_p_*.npy' --rig yinyang --task volume:p-wave --size 400x390 "
    "--out out/seismic.db": check_seismic_chain,
}


def main():
    readme, panoptes, work = sys.argv[1], os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3])
    repo = os.path.dirname(os.path.abspath(readme))
    env = dict(os.environ)
    env["PATH"] = os.path.join(work, "bin") + os.pathsep + env["PATH"]
    blocks = snippets(readme)
    commands = [(n, c) for lang, start, text in blocks if lang == "sh" for n, c in shell_commands(text, start)]
    stale = sorted((set(SKIPPED) | set(CHECKS)) - {c for _, c in commands})
    if stale:
        print("FAIL: SKIPPED or CHECKS name commands README no longer has: " + "; ".join(stale))
        sys.exit(1)
    prepare(work, panoptes, repo, env)
    ran = skipped = 0
    for lang, start, text in blocks:
        if lang == "python":
            script = os.path.join(work, f"readme_{start}.py")
            with open(script, "w") as f:
                f.write(PYTHON_PRELUDE + text)
            seconds = run(["/usr/bin/python3", script], work, env, f"README.md:{start} (python block)")
            print(f"ok    README.md:{start} python block ({seconds:.1f} s)")
            ran += 1
            continue
        for number, command in shell_commands(text, start):
            if command in SKIPPED:
                print(f"skip  README.md:{number} {command}\n      ({SKIPPED[command]})")
                skipped += 1
                continue
            seconds = run(["bash", "-euo", "pipefail", "-c", command], work, env, f"README.md:{number} `{command}`")
            print(f"ok    README.md:{number} {command} ({seconds:.1f} s)")
            ran += 1
            if command in CHECKS:
                print("ok    " + CHECKS[command](work))
    print(f"readme: {ran} snippets ran, {skipped} skipped (reasons above)")


if __name__ == "__main__":
    main()
