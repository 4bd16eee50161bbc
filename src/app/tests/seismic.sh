#!/usr/bin/env bash
# `panoptes seismic`: a tiny run writes one CSV per receiver, a report and field snapshots (.npy,
# readable by `panoptes render`); bad configs fail cleanly before any step; --help documents the
# keys; 2 ranks give identical seismograms and snapshots.
set -euo pipefail
panoptes=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cat > "$dir/tiny.toml" <<'TOML'
[grid]
nx = 24
ny = 24
nz = 20
h = 50.0
[time]
steps = 40
[medium]
type = "homogeneous"
rho = 2000.0
vp = 2000.0
vs = 1100.0
qp = 80.0
qs = 40.0
[boundary]
pml_cells = 6
[[source]]
type = "explosion"
position = [600.0, 600.0, 400.0]
m0 = 1e14
stf = "ricker"
frequency = 4.0
[[receiver]]
name = "top"
position = [700.0, 600.0, 0.0]
[[receiver_line]]
name = "line"
start = [400.0, 600.0, 200.0]
end = [800.0, 600.0, 200.0]
count = 2
[output]
snapshot_fields = ["vz", "phi_p", "sxz", "phi_s"]
snapshot_every = 20
TOML
"$panoptes" seismic --help | grep "receiver_line" >/dev/null
"$panoptes" seismic "$dir/tiny.toml" --out "$dir/out" -q
for f in top line_000 line_001; do
  test -s "$dir/out/$f.csv" || { echo "missing $f.csv"; exit 1; }
done
head -1 "$dir/out/top.csv" | grep -x "time,vx,vy,vz" >/dev/null
test "$(wc -l < "$dir/out/top.csv")" -eq 41
# Some motion arrived at the surface receiver.
awk -F, 'NR>1 && ($4 > 1e-12 || $4 < -1e-12) {found=1} END {exit !found}' "$dir/out/top.csv"
grep -q "cell updates per second" "$dir/out/report.txt"
# Snapshots: .npy float32 of the global grid, shape (nz, ny, nx), after steps 20 and 40.
snaps="vz_000020 vz_000040 phi_p_000020 phi_p_000040 sxz_000020 sxz_000040 phi_s_000020 phi_s_000040"
for f in $snaps; do
  npy="$dir/out/snapshots/$f.npy"
  test -s "$npy" || { echo "missing snapshot $f.npy"; exit 1; }
  head -c 128 "$npy" | grep -a "'descr': '<f4', 'fortran_order': False, 'shape': (20, 24, 24)" >/dev/null \
    || { echo "bad .npy header in $f.npy: $(head -c 100 "$npy" | tr -d '\0')"; exit 1; }
  test "$(stat -c %s "$npy")" -eq $((128 + 20 * 24 * 24 * 4)) || { echo "bad size of $f.npy"; exit 1; }
done
# Each beside its sidecar (issue 41): grid (each field at its own staggered points), units, time, z down.
test "$(ls "$dir/out/snapshots" | wc -l)" -eq 16
/usr/bin/python3 - "$dir/out/snapshots" "$dir/out/report.txt" <<'EOF'
import json, re, sys
snaps, report = sys.argv[1], open(sys.argv[2]).read()
dt = float(re.search(r"^dt: (\S+) s", report, re.M).group(1))
want = {"vz": ("m/s", [0, 0, 25.0], -0.5), "phi_p": ("1/s", [0, 0, 0], -0.5), "sxz": ("Pa", [25.0, 0, 25.0], 0.0),
        "phi_s": ("1/s", [0, 0, 0], -0.5)}
for field, (units, origin, shift) in want.items():
    for step in (20, 40):
        name = f"{field}_{step:06d}"
        s = json.load(open(f"{snaps}/{name}.json"))
        got = {k: s.get(k) for k in ("format", "version", "data", "field", "field_units", "dims", "origin", "spacing",
                                     "length_units", "up_axis", "time_units", "step")}
        exp = {"format": "panoptes field sidecar", "version": 1, "data": name + ".npy", "field": field, "field_units": units,
               "dims": [24, 24, 20], "origin": origin, "spacing": [50.0, 50.0, 50.0], "length_units": "m",
               "up_axis": "z_down", "time_units": "s", "step": step}
        if got != exp:
            sys.exit(f"{name}.json: {got}, expected {exp}")
        # velocities and phi at (step - 1/2) dt, stresses at step dt (dt as the report prints it: 6 digits)
        if abs(s["time"] - (step + shift) * dt) > 1e-5 * step * dt:
            sys.exit(f"{name}.json: time {s['time']}, expected {(step + shift) * dt}")
EOF
# The wave has reached the grid: the last vz snapshot is not all zeros.
test "$(tail -c $((20 * 24 * 24 * 4)) "$dir/out/snapshots/vz_000040.npy" | tr -d '\0' | wc -c)" -gt 0
grep -q "snapshots: 2 x {vz, phi_p, sxz, phi_s}" "$dir/out/report.txt"
# They load in `panoptes render` (its .npy reader) as a time series of two volumes.
"$panoptes" render "$dir/out/snapshots/phi_p_*.npy" --rig fibonacci:2 --size 32x24 --out "$dir/db" > "$dir/render.txt"
grep -q "2 cameras x 1 tasks = 2 streams, 2 frames of 32x24" "$dir/render.txt" \
  || { echo "render of snapshots: $(cat "$dir/render.txt")"; exit 1; }
# ... oriented and labelled by their sidecars: z is depth, metres, seconds, phi_p in 1/s.
/usr/bin/python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))
got = (m["domain"].get("up_axis"), m["domain"].get("units"), m.get("time_units"), [(f["name"], f["units"]) for f in m["fields"]])
if got != ("z_down", "m", "s", [("phi_p", "1/s")]): sys.exit(f"render of snapshots: {got}")' "$dir/db/panoptes.json"
# Errors: unknown key, wrong type, CFL violation, receiver outside; each one line, exit 1.
expect_error() {
  local pattern=$1
  if "$panoptes" seismic "$dir/bad.toml" --out "$dir/bad" -q 2> "$dir/err"; then echo "accepted: $pattern"; exit 1; fi
  grep -q "$pattern" "$dir/err" || { echo "expected '$pattern', got:"; cat "$dir/err"; exit 1; }
  test ! -e "$dir/bad/top.csv"
}
sed 's/^h = 50.0/h = 50.0\nspacing = 3/' "$dir/tiny.toml" > "$dir/bad.toml"; expect_error "grid.spacing: unknown key"
sed 's/^steps = 40/steps = "40"/' "$dir/tiny.toml" > "$dir/bad.toml"; expect_error "time.steps: expected an integer"
sed 's/^steps = 40/steps = 40\ndt = 0.1/' "$dir/tiny.toml" > "$dir/bad.toml"; expect_error "largest stable time step"
sed 's/^position = \[700.0, 600.0, 0.0\]/position = [700.0, 600.0, 5000.0]/' "$dir/tiny.toml" > "$dir/bad.toml"
expect_error "receiver 'top'"
sed 's/^snapshot_fields = .*/snapshot_fields = ["vz", "vq"]/' "$dir/tiny.toml" > "$dir/bad.toml"
expect_error "output.snapshot_fields\[1\]: unknown field 'vq' (expected one of vx, vy, vz, sxx"
if "$panoptes" seismic "$dir/missing.toml" 2>/dev/null; then echo "missing config accepted"; exit 1; fi
# Under MPI (when available), 2 ranks give the same seismograms.
if command -v mpiexec >/dev/null && "$panoptes" version >/dev/null; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1
  if mpiexec --oversubscribe -np 2 "$panoptes" seismic "$dir/tiny.toml" --out "$dir/out2" -q; then
    cmp "$dir/out/top.csv" "$dir/out2/top.csv" || { echo "2 ranks differ from 1"; exit 1; }
    for f in $snaps; do
      cmp "$dir/out/snapshots/$f.npy" "$dir/out2/snapshots/$f.npy" || { echo "2-rank snapshot $f differs"; exit 1; }
      cmp "$dir/out/snapshots/$f.json" "$dir/out2/snapshots/$f.json" || { echo "2-rank sidecar $f differs"; exit 1; }
    done
  else
    echo "mpiexec run failed"; exit 1
  fi
fi
echo "seismic: ok"
