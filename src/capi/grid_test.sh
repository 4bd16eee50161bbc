#!/usr/bin/env bash
# A Yin-Yang grid through the Fortran module (grid_test.f90: Yin x-fastest, Yang z-fastest with
# layout='zxy', two snapshots of an analytic shell field) must give exactly the frames of the same
# coordinates and values through the C API (grid_reference.py, ctypes); then the Fortran refusals.
set -euo pipefail
bin=$1 config=$2 pypath=$3 work=$4 lib=$5
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
mkdir -p "$work/fortran" "$work/capi" "$work/errors"
fail() { echo "grid_test: FAIL: $*" >&2; exit 1; }
PYTHONPATH=$pypath /usr/bin/python3 -c 'import panoptes' 2>/dev/null || { echo "python package not built: skipped"; exit 77; }

(cd "$work/fortran" && "$bin" yinyang "$config" .) >"$work/fortran.log" 2>&1 || { cat "$work/fortran.log"; fail "fortran run"; }
tail -1 "$work/fortran.log"

PYTHONPATH=$pypath:$here /usr/bin/python3 - "$work" "$config" "$lib" <<'PY' || fail "frames differ"
import sys, os, numpy as np, grid_reference
work, config, lib = sys.argv[1:4]
nr, nth, nph = 7, 18, 40
c = np.fromfile(f"{work}/fortran/coords.bin", dtype=np.float64)
coords = [c[:nr], c[nr:nr + nth], c[nr + nth:]]
snapshots = []
for s in range(2):
    v = np.fromfile(f"{work}/fortran/field_{s}.bin", dtype=np.float64).reshape(2, nph, nth, nr)
    snapshots.append((0.7 * s, [v[0], v[1]]))
os.chdir(f"{work}/capi")
grid_reference.render(lib, open(config).read(), "yinyang", coords, snapshots, points=48)
worst, frames = grid_reference.compare(f"{work}/capi/db", f"{work}/fortran/db")
print(f"fortran vs C API: {frames} frames, largest difference {worst}/255")
import panoptes
db = panoptes.open(f"{work}/fortran/db")
bright = max(int(db.frame(c, 0, f).max()) for c in range(db.camera_count) for f in range(db.frame_count))
print(f"brightest pixel {bright}/255 (the shell is drawn, not an empty frame)")
assert bright > 40
sys.exit(0 if worst == 0 else 1)
PY

(cd "$work/errors" && "$bin" errors "$config" .) >"$work/errors.log" 2>&1 || { cat "$work/errors.log"; fail "errors"; }
grep -q 'every refusal as expected' "$work/errors.log" || { cat "$work/errors.log"; fail "errors"; }
grep -q '^panoptes: error: panoptes_set_grid_spherical: spherical grid: r coordinates are not strictly increasing' \
  "$work/errors.log" || { cat "$work/errors.log"; fail "no error line printed"; }
tail -1 "$work/errors.log"
echo "grid_test: OK"
