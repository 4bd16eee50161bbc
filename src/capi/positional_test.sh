#!/usr/bin/env bash
# The Fortran module's panoptes_field in its old positional form (ierr 4th, as before issue 28), its
# positional layout form and its keyword forms (issue 42, point 9): positional_test.f90 must COMPILE
# against the built module (a compile failure is this test's failure, with the compiler's message),
# run without a refusal it did not expect, and give identical frames for u(x,y,z) and the same values
# as v(z,x,y) bound by each form.
set -euo pipefail
src=$1 config=$2 pypath=$3 work=$4 fc=$5 moddir=$6 flib=$7 clib=$8
rm -rf "$work"
mkdir -p "$work"
fail() { echo "positional_test: FAIL: $*" >&2; exit 1; }
PYTHONPATH=$pypath /usr/bin/python3 -c 'import panoptes' 2>/dev/null || { echo "python package not built: skipped"; exit 77; }

"$fc" -I"$moddir" -o "$work/positional_test" "$src" "$flib" "$clib" -Wl,-rpath,"$(dirname "$clib")" \
  >"$work/compile.log" 2>&1 || { cat "$work/compile.log"; fail "does not compile against the module"; }
echo "compiled: every form of panoptes_field"
(cd "$work" && ./positional_test "$config") >"$work/run.log" 2>&1 || { cat "$work/run.log"; fail "run"; }
grep -q 'every form as expected' "$work/run.log" || { cat "$work/run.log"; fail "run"; }

PYTHONPATH=$pypath /usr/bin/python3 - "$work/db" <<'PY' || fail "frames differ"
import sys, numpy as np, panoptes
db = panoptes.open(sys.argv[1])
assert db.status == "complete" and db.frame_count == 4, (db.status, db.frame_count)
worst, worst4, bright = 0, 0, 0
for c in range(db.camera_count):
    for t in range(db.task_count):
        f0 = db.frame(c, t, 0).astype(int)
        bright = max(bright, int(f0.max()))
        for f in (1, 2):
            worst = max(worst, int(np.abs(db.frame(c, t, f).astype(int) - f0).max()))
        worst4 = max(worst4, int(np.abs(db.frame(c, t, 3).astype(int) - f0).max()))
print(f"frames 1, 2 vs 0: largest difference {worst}/255; real(4) frame 3: {worst4}/255; brightest {bright}/255")
sys.exit(0 if worst == 0 and worst4 <= 2 and bright > 40 else 1)
PY
echo "positional_test: OK"
