#!/usr/bin/env bash
# CLI test of `panoptes run`: a tiny seismic run with in-situ visualization (1 process and, if mpirun
# is available, 2 ranks) gives a complete database; configuration errors stop before the run.
set -euo pipefail
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

cat > tiny.toml <<'TOML'
[grid]
nx = 28
ny = 24
nz = 20
h = 100.0
[time]
steps = 40
[medium]
type = "homogeneous"
rho = 2500.0
vp = 4000.0
vs = 2300.0
[boundary]
pml_cells = 5
[[source]]
type = "double_couple"
position = [1400.0, 1200.0, 900.0]
strike = 30.0
dip = 45.0
rake = 90.0
m0 = 1.0e15
stf = "ricker"
frequency = 6.0
[output]
dir = "tiny_db"
[image]
width = 40
height = 32
[rig]
spec = "fibonacci:4"
[schedule]
every_steps = 10
[[task]]
name = "p"
field = "phi_p"
preset = "p-wave"
[[task]]
name = "both"
type = "volume2"
fields = ["phi_p", "phi_s"]
TOML

check_complete() {
  local out
  out=$("$bin" info --json "$1")
  echo "$out" | grep -E '"status": *"complete"' >/dev/null || { echo "FAIL: $1 not complete: $out"; exit 1; }
  echo "$out" | grep -E '"frames": *4' >/dev/null || { echo "FAIL: $1 does not have 4 frames: $out"; exit 1; }
}

"$bin" run tiny.toml > run1.log 2>&1 || { cat run1.log; echo "FAIL: run"; exit 1; }
grep -q "4 cameras x 2 tasks = 8 streams, 4 frames each" run1.log || { cat run1.log; echo "FAIL: summary"; exit 1; }
grep -q "raw fields" run1.log || { cat run1.log; echo "FAIL: no raw-size comparison"; exit 1; }
check_complete tiny_db

# An existing database is refused unless --overwrite.
if "$bin" run tiny.toml > again.log 2>&1; then echo "FAIL: existing database overwritten"; exit 1; fi
"$bin" run tiny.toml --overwrite -q > /dev/null

if command -v mpirun > /dev/null; then
  mpirun --oversubscribe -np 2 "$bin" run tiny.toml --out tiny_db2 -q > mpi.log 2>&1 || { cat mpi.log; echo "FAIL: mpirun"; exit 1; }
  check_complete tiny_db2
fi

expect_error() {  # $1 = sed expression applied to tiny.toml, $2 = expected message part
  sed -e "$1" tiny.toml > bad.toml
  if "$bin" run bad.toml --out bad_db > bad.log 2>&1; then echo "FAIL: accepted ($1)"; exit 1; fi
  grep -qF -- "$2" bad.log || { echo "FAIL: for ($1) expected \"$2\", got:"; cat bad.log; exit 1; }
  [ ! -e bad_db ] || { echo "FAIL: ($1) created a database before failing"; exit 1; }
}
expect_error 's/^width = 40/widht = 40/' 'image.widht: unknown key'
expect_error 's/^every_steps = 10/every_steps = "often"/' 'schedule.every_steps: expected an integer'
expect_error 's/field = "phi_p"/field = "pressure"/' 'field "pressure"'
expect_error 's/^nx = 28/nx = "big"/' 'grid.nx'
expect_error 's/^spec = "fibonacci:4"/spec = "cube"/' 'rig.spec'
expect_error 's/^preset = "p-wave"/preset = "violet"/' 'unknown preset "violet"'
echo "run.sh: ok"
