#!/usr/bin/env bash
# Fortran arrays as real codes hold them (issue 28), through the Panoptes module. On 2 x 2 ranks, a
# z-fastest array (layout='zxy') and a real(4) sleeved, padded z-fastest array handed over as a section,
# both with a face-only halo (stale edge/corner ghosts), must give exactly the frames of the x-fastest
# array with a full halo (every camera, task and snapshot); the same on
# 1 rank for z-fastest; and 2 x 2 ranks must match 1 rank within the rank bar of insitu_mpi_test
# (PSNR >= 45 dB: partial images composite in another order, measured worst difference 4/255). Then the
# refusals (layout_test errors), and an expression (a temporary the library would keep the address of)
# refused at compile time.
set -euo pipefail
bin=$1 config=$2 pypath=$3 work=$4 fc=$5 moddir=$6
rm -rf "$work"
mkdir -p "$work"
fail() { echo "layout_test: FAIL: $*" >&2; exit 1; }
PYTHONPATH=$pypath /usr/bin/python3 -c 'import panoptes' 2>/dev/null || { echo "python package not built: skipped"; exit 77; }

run() {  # name ranks mode
  mkdir -p "$work/$1"
  (cd "$work/$1" && mpiexec --oversubscribe -np "$2" "$bin" "$3" "$config") >"$work/$1.log" 2>&1 ||
    { cat "$work/$1.log"; fail "$1"; }
  tail -1 "$work/$1.log"
}
run np1_xyz 1 xyz
run np1_zxy 1 zxy
run np4_xyz 4 xyz
run np4_zxy 4 zxy
run np4_sleeve 4 sleeve

PYTHONPATH=$pypath /usr/bin/python3 - "$work" <<'PY' || fail "frames differ"
import math, sys, numpy as np, panoptes
work = sys.argv[1]

def compare(ref_run, run):
    ref, db = panoptes.open(f"{work}/{ref_run}/db"), panoptes.open(f"{work}/{run}/db")
    for d in (ref, db):
        assert d.status == "complete" and d.frame_count == 3, (d.path, d.status, d.frame_count)
    np.testing.assert_allclose(db.times, ref.times)
    worst, psnr, frames = 0, math.inf, 0
    for c in range(ref.camera_count):
        for t in range(ref.task_count):
            for f in range(ref.frame_count):
                a, b = ref.frame(c, t, f).astype(int), db.frame(c, t, f).astype(int)
                worst = max(worst, int(np.abs(a - b).max()))
                mse = float(((a - b) ** 2).mean())
                psnr = min(psnr, math.inf if mse == 0 else 10 * math.log10(255 ** 2 / mse))
                frames += 1
    print(f"{run} vs {ref_run}: {frames} frames, largest difference {worst}/255, worst PSNR {psnr:.1f} dB")
    return worst, psnr

bad = False
for ref_run, run in (("np1_xyz", "np1_zxy"), ("np4_xyz", "np4_zxy"), ("np4_xyz", "np4_sleeve")):
    worst, _ = compare(ref_run, run)
    bad |= worst != 0  # the same decomposition: the layout must not change a single pixel
_, psnr = compare("np1_xyz", "np4_xyz")
bad |= psnr < 45
sys.exit(1 if bad else 0)
PY

(cd "$work" && mkdir -p errors && cd errors && mpiexec -np 1 "$bin" errors "$config") >"$work/errors.log" 2>&1 ||
  { cat "$work/errors.log"; fail "errors"; }
grep -q 'every refusal as expected' "$work/errors.log" || { cat "$work/errors.log"; fail "errors"; }
# The library printed each refusal once, to stderr, without a backtrace or ERROR STOP.
grep -q '^panoptes: error: panoptes_set_field_layout: field "T" has shape (22, 30, 26)' "$work/errors.log" ||
  { cat "$work/errors.log"; fail "no error line printed"; }
! grep -Eiq 'backtrace|error stop' "$work/errors.log" || { cat "$work/errors.log"; fail "backtrace or ERROR STOP"; }
echo "refusals: $(grep -c '^panoptes: error:' "$work/errors.log") error lines, as expected"

# An expression would be passed as a temporary freed after the call: the module's INTENT(INOUT) dummy makes
# the compiler refuse it (and a vector-subscripted section) instead of a crash at the next snapshot.
for arg in 'u(:, 1:3, :)' '2 * u' 'u(:, [1, 3], :)'; do
  cat >"$work/temporary.f90" <<F90
program temporary
  use panoptes
  real(8), allocatable, target :: u(:, :, :)
  type(panoptes_t) :: viz
  allocate(u(4, 4, 4))
  call panoptes_field(viz, 'T', $arg)
end program
F90
  if [ "$arg" = 'u(:, 1:3, :)' ]; then  # the control: a section compiles (and is read in place)
    "$fc" -fsyntax-only -I"$moddir" "$work/temporary.f90" >"$work/temporary.log" 2>&1 ||
      { cat "$work/temporary.log"; fail "a section does not compile"; }
  elif "$fc" -fsyntax-only -I"$moddir" "$work/temporary.f90" >"$work/temporary.log" 2>&1; then
    fail "panoptes_field(viz, 'T', $arg) compiled: a temporary would be kept"
  else
    echo "refused at compile time: panoptes_field(viz, 'T', $arg): $(grep -m1 -i 'error' "$work/temporary.log")"
  fi
done
echo "layout_test: OK"
