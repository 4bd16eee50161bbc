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
if grep -q "showed nothing" run1.log; then cat run1.log; echo "FAIL: a visible run warned of empty frames"; exit 1; fi

# A scale far above the field (a fixed reference 1e5 times the waves' 1/s) leaves every frame of the p
# task black: the run says so at its end instead of leaving it to whoever opens the movies.
printf '[render.field.phi_p]\nreference = "fixed"\nvalue = 10.0\n' | cat tiny.toml - > dark.toml
"$bin" run dark.toml --out dark_db > dark.log 2>&1 || { cat dark.log; echo "FAIL: run dark.toml"; exit 1; }
grep -qF 'task "p" showed nothing in 4 of 4 frames (0-3) from any camera' dark.log ||
  { cat dark.log; echo "FAIL: no warning for a task that showed nothing"; exit 1; }
grep -qF "fixed reference 10" dark.log || { cat dark.log; echo "FAIL: the warning does not name the reference"; exit 1; }

# An existing database is refused unless --overwrite.
if "$bin" run tiny.toml > again.log 2>&1; then echo "FAIL: existing database overwritten"; exit 1; fi
grep -q -- "add --overwrite" again.log || { cat again.log; echo "FAIL: the refusal does not name --overwrite"; exit 1; }
"$bin" run tiny.toml --overwrite -q > /dev/null

# Issue 42: [[receiver]] tables are not ignored: `run` writes their seismograms as `seismic` does, into
# the database's seismograms/ folder (before, the table was accepted and nothing was written).
check_seismograms() {  # DB
  local csv=$1/seismograms/top.csv
  [ -f "$csv" ] || { echo "FAIL: $1 has no seismogram for receiver 'top'"; ls -R "$1" | head; exit 1; }
  [ "$(head -n 1 "$csv")" = "time,vx,vy,vz" ] || { echo "FAIL: $csv header: $(head -n 1 "$csv")"; exit 1; }
  [ "$(wc -l < "$csv")" = 41 ] || { echo "FAIL: $csv has $(wc -l < "$csv") lines, expected 1 + 40 steps"; exit 1; }
  awk -F, 'NR > 1 && ($2 != 0 || $3 != 0 || $4 != 0) { moved = 1 } END { exit !moved }' "$csv" ||
    { echo "FAIL: $csv records no motion"; exit 1; }
}
printf '[[receiver]]\nname = "top"\nposition = [1400.0, 1200.0, 0.0]\n' | cat tiny.toml - > rec.toml
"$bin" run rec.toml --out rec_db -q > rec.log 2>&1 || { cat rec.log; echo "FAIL: run with a receiver"; exit 1; }
check_seismograms rec_db
grep -q "seismograms: 1 receiver" rec.log || { cat rec.log; echo "FAIL: the run does not say where the seismograms are"; exit 1; }
# A rerun with --overwrite and without that receiver leaves no stale seismogram of the old run.
"$bin" run tiny.toml --out rec_db --overwrite -q > rec2.log 2>&1 || { cat rec2.log; echo "FAIL: overwrite"; exit 1; }
[ ! -e rec_db/seismograms/top.csv ] || { echo "FAIL: the old run's seismogram top.csv survived --overwrite"; exit 1; }

if command -v mpirun > /dev/null; then
  mpirun --oversubscribe -np 2 "$bin" run tiny.toml --out tiny_db2 -q > mpi.log 2>&1 || { cat mpi.log; echo "FAIL: mpirun"; exit 1; }
  check_complete tiny_db2
  mpirun --oversubscribe -np 2 "$bin" run dark.toml --out dark_db2 > mpi_dark.log 2>&1 || { cat mpi_dark.log; echo "FAIL: mpirun dark.toml"; exit 1; }
  [ "$(grep -c 'task "p" showed nothing in 4 of 4 frames' mpi_dark.log)" = 1 ] ||
    { cat mpi_dark.log; echo "FAIL: 2 ranks: not one warning for the black task"; exit 1; }
  mpirun --oversubscribe -np 2 "$bin" run rec.toml --out rec_db2 -q > mpi_rec.log 2>&1 || { cat mpi_rec.log; echo "FAIL: mpirun with a receiver"; exit 1; }
  check_seismograms rec_db2
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

# Issue 15 (FIFOs and layer order: unit tests FileRead.*, SeismicConfig.*): absurd configurations are refused at once, in one line naming the number and the limit,
# before any database exists (never std::bad_alloc, a hang or gigabytes of memory).
expect_one_line() {  # $1 = what, $2 = expected message part; runs bad.toml
  local start=$SECONDS
  if timeout 20 "$bin" run bad.toml --out bad_db > bad.log 2>&1; then echo "FAIL: accepted ($1)"; exit 1; fi
  grep -qF -- "$2" bad.log || { echo "FAIL: for ($1) expected \"$2\", got:"; cat bad.log; exit 1; }
  [ "$(wc -l < bad.log)" = 1 ] || { echo "FAIL: ($1) not one line:"; cat bad.log; exit 1; }
  grep -q "bad_alloc" bad.log && { echo "FAIL: ($1) bad_alloc"; exit 1; }
  (( SECONDS - start < 15 )) || { echo "FAIL: ($1) took $((SECONDS - start)) s"; exit 1; }
  [ ! -e bad_db ] || { echo "FAIL: ($1) created a database before failing"; exit 1; }
}
sed -e 's/^nx = 28/nx = 2000/; s/^ny = 24/ny = 2000/; s/^nz = 20/nz = 2000/' tiny.toml > bad.toml
expect_one_line "2000^3 grid" "this run needs about"
grep -qF "pass --force" bad.log || { cat bad.log; echo "FAIL: no --force hint"; exit 1; }
sed -e 's/^steps = 40/steps = 2147483647/' tiny.toml > bad.toml
printf '[[receiver_line]]\nname = "l"\nstart = [600.0, 600.0, 0.0]\nend = [1500.0, 1500.0, 0.0]\ncount = 100\n' >> bad.toml
expect_one_line "steps near 2^31" "receiver traces"
sed -e 's/^nx = 28/nx = 4294967336/' tiny.toml > bad.toml
expect_one_line "nx narrowed" "grid.nx: 4294967336 is out of range"
sed -e 's|^spec = "fibonacci:4"|spec = "file:/dev/zero"|' tiny.toml > bad.toml
expect_one_line "rig from /dev/zero" "/dev/zero: is a character device"
# One movie file per stream (layout = "files"): the open-file limit refuses 10^7 movies at once. (The
# packed layout opens 2 files per rank whatever the streams: there the rig's size is only memory and time.)
for rig in "fibonacci:10000000" "fibonacci:1000000@2,3,4,5,6"; do
  sed -e "s|^spec = \"fibonacci:4\"|spec = \"$rig\"|" -e 's|^dir = "tiny_db"|dir = "tiny_db"\nlayout = "files"|' tiny.toml > bad.toml
  if timeout 20 "$bin" run bad.toml --out bad_db > bad.log 2>&1; then echo "FAIL: accepted $rig"; exit 1; fi
  grep -qE "open-file limit|needs about" bad.log || { echo "FAIL: $rig:"; cat bad.log; exit 1; }
  [ "$(wc -l < bad.log)" = 1 ] && [ ! -e bad_db ] || { echo "FAIL: $rig:"; cat bad.log; exit 1; }
done
sed -e 's/^every_steps = 10/every_time = 1e-300/' tiny.toml > bad.toml
expect_one_line "every_time = 1e-300" "is shorter than the solver's time step"
sed -e 's/^every_steps = 10/every_steps = 1000/' tiny.toml > bad.toml
expect_one_line "no snapshot" "the schedule takes no snapshot in 40 steps"
# 16384 x 16384 for every camera, and a sweep of 16 windows: hundreds of GB of partial images.
sed -e 's/^width = 40/width = 16384/; s/^height = 32/height = 16384/' \
    -e 's/^preset = "p-wave"/preset = "p-wave"\nwindows = [[0,1],[0,2],[0,3],[0,4],[0,5],[0,6],[0,7],[0,8],[0,9],[0,10],[0,11],[0,12],[0,13],[0,14],[0,15],[0,16]]/' \
    tiny.toml > bad.toml
expect_one_line "16384^2 images" "partial images"
sed -e 's/^type = "homogeneous"/type = "layered"\n[[medium.layer]]\ntop = -100.0/' tiny.toml > bad.toml
expect_one_line "layer above the surface" "must start at the surface"
# The limit can be set explicitly (batch systems without cgroups); --force runs anyway.
cp tiny.toml bad.toml
PANOPTES_MEMORY_LIMIT=1M expect_one_line "1 MB limit" "available (PANOPTES_MEMORY_LIMIT)"
PANOPTES_MEMORY_LIMIT=1M "$bin" run tiny.toml --out forced_db --force -q > forced.log 2>&1 || { cat forced.log; echo "FAIL: --force"; exit 1; }
check_complete forced_db
echo "run.sh: ok"
