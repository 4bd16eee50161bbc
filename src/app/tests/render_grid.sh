#!/usr/bin/env bash
# `panoptes render --grid GRID.toml` (issue 33): .npy volumes on spherical, Yin-Yang and rectilinear
# grids with .npy coordinate arrays, resampled by the in-situ grid stage; the manifest records the
# grid; bad coordinates, lengths and Yin-Yang shapes are refused with one clear line.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "render_grid.sh: $*" >&2; exit 1; }
/usr/bin/python3 -c 'import numpy' 2>/dev/null || { echo "numpy missing: skipped"; exit 0; }

/usr/bin/python3 - "$tmp" <<'PY'
import sys, numpy as np
d = sys.argv[1]
def field(r, th, ph, t, yang=False):
    P, T, R = np.meshgrid(ph, th, r, indexing="ij")
    a, b, c = R * np.sin(T) * np.cos(P), R * np.sin(T) * np.sin(P), R * np.cos(T)
    x, y, z = (-a, c, b) if yang else (a, b, c)
    return np.sin(np.pi * (R - r[0]) / (r[-1] - r[0])) * (0.5 + 0.6 * ((x * x - y * y) * np.cos(2 * t)) / (R * R))
r = np.linspace(0.35, 1.0, 8)
th = np.linspace(0.05, np.pi - 0.05, 18)
ph = np.linspace(-np.pi, np.pi, 37)[:-1]
np.save(f"{d}/r.npy", r); np.save(f"{d}/theta.npy", th); np.save(f"{d}/phi.npy", ph)
for s in range(2):
    np.save(f"{d}/shell_{s}.npy", field(r, th, ph, 0.5 * s).astype(np.float32))
np.save(f"{d}/r_bad.npy", np.array([0.35, 0.5, 0.5, 1.0]))
np.save(f"{d}/coords_2d.npy", np.zeros((2, 3)))
# Yin-Yang: one patch's coordinates, volumes (2, nphi, ntheta, nr).
dt, dp = (np.pi / 2) / 11, 1.5 * np.pi / 31
yt, yp = np.pi / 4 - 2 * dt + dt * np.arange(16), -0.75 * np.pi - 2 * dp + dp * np.arange(36)
np.save(f"{d}/yy_theta.npy", yt); np.save(f"{d}/yy_phi.npy", yp); np.save(f"{d}/yy_theta_narrow.npy", yt[3:-3])
np.save(f"{d}/yy.npy", np.stack([field(r, yt, yp, 0.0), field(r, yt, yp, 0.0, yang=True)]))
np.save(f"{d}/yy_one_patch.npy", field(r, yt, yp, 0.0))
# Rectilinear: stretched x.
x = np.cumsum(np.linspace(0.5, 1.5, 14)); y = np.linspace(0, 6, 10); z = np.linspace(0, 4, 8)
np.save(f"{d}/x.npy", x); np.save(f"{d}/y.npy", y); np.save(f"{d}/z.npy", z)
Z, Y, X = np.meshgrid(z, y, x, indexing="ij")
np.save(f"{d}/box.npy", np.exp(-((X - 6) ** 2 + (Y - 3) ** 2 + (Z - 2) ** 2) / 4))
PY

cat > "$tmp/shell.toml" <<'EOF2'
[grid]
kind = "spherical"
r = "r.npy"
theta = "theta.npy"
phi = "phi.npy"
points = 40
EOF2
"$panoptes" render "$tmp/shell_*.npy" --grid "$tmp/shell.toml" --rig fibonacci:3 --task volume:diverging:-1:1 \
  --size 40x32 -q --out "$tmp/shell_db" > "$tmp/out.txt" || fail "spherical render failed"
grep -q "3 cameras x 1 tasks = 3 streams, 2 frames of 40x32" "$tmp/out.txt" || fail "summary: $(cat "$tmp/out.txt")"
grep -q '"grid":"spherical 8x18x36, r in \[0.35, 1\]' "$tmp/shell_db/panoptes.json" || fail "manifest without the grid"
grep -q '"dims":\[40,40,40\]' "$tmp/shell_db/panoptes.json" || fail "not resampled onto 40 points: $(head -c 600 "$tmp/shell_db/panoptes.json")"
grep -q -- "--grid $tmp/shell.toml" "$tmp/shell_db/panoptes.json" || fail "--grid not in the recorded command line"

sed -e 's/spherical/yinyang/' -e 's/"theta.npy"/"yy_theta.npy"/' -e 's/"phi.npy"/"yy_phi.npy"/' "$tmp/shell.toml" > "$tmp/yy.toml"
"$panoptes" render "$tmp/yy.npy" --grid "$tmp/yy.toml" --rig fibonacci:3 --task volume:diverging:-1:1 \
  --size 40x32 -q --out "$tmp/yy_db" > /dev/null || fail "Yin-Yang render failed"
grep -q '"grid":"yinyang 8x16x36' "$tmp/yy_db/panoptes.json" || fail "manifest without the Yin-Yang grid"

printf '[grid]\nkind = "rectilinear"\nx = "x.npy"\ny = "y.npy"\nz = "z.npy"\n' > "$tmp/box.toml"
"$panoptes" render "$tmp/box.npy" --grid "$tmp/box.toml" --rig fibonacci:2 --size 32x32 -q --out "$tmp/box_db" > /dev/null ||
  fail "rectilinear render failed"
grep -q '"grid":"rectilinear 14x10x8' "$tmp/box_db/panoptes.json" || fail "manifest without the rectilinear grid"

# Refusals: one line each, naming the file, the key or the shape.
refuse() {  # expected-text toml volume [extra args]
  local want=$1 toml=$2 vol=$3
  shift 3
  if "$panoptes" render "$vol" --grid "$toml" --rig fibonacci:2 --size 32x32 -q --out "$tmp/bad_db" "$@" \
       > /dev/null 2> "$tmp/err.txt"; then
    fail "accepted (expected: $want)"
  fi
  [ "$(wc -l < "$tmp/err.txt")" = 1 ] || fail "not one line: $(cat "$tmp/err.txt")"
  grep -qF -- "$want" "$tmp/err.txt" || fail "expected '$want', got: $(cat "$tmp/err.txt")"
  rm -rf "$tmp/bad_db"
}
sed 's/"r.npy"/"r_bad.npy"/' "$tmp/shell.toml" > "$tmp/bad_r.toml"
refuse "r coordinates are not strictly increasing: r[1] = 0.5, r[2] = 0.5" "$tmp/bad_r.toml" "$tmp/shell_0.npy"
refuse "array of shape (36, 16, 8); expected (36, 18, 8), the grid's (n2, n1, n0) points" "$tmp/shell.toml" "$tmp/yy_one_patch.npy"
refuse "expected (2, 36, 16, 8), a Yin-Yang volume (2 patches" "$tmp/yy.toml" "$tmp/yy_one_patch.npy"
sed 's/"yy_theta.npy"/"yy_theta_narrow.npy"/' "$tmp/yy.toml" > "$tmp/narrow.toml"
refuse "leave a gap" "$tmp/narrow.toml" "$tmp/yy.npy"
sed 's/"r.npy"/"coords_2d.npy"/' "$tmp/shell.toml" > "$tmp/r2d.toml"
refuse "grid.r: array of 2 dimensions; expected a 1-D array of coordinates" "$tmp/r2d.toml" "$tmp/shell_0.npy"
refuse "--spacing and --origin are for uniform volumes" "$tmp/shell.toml" "$tmp/shell_0.npy" --spacing 1,1,1
printf '[grid]\nkind = "spherical"\nr = "r.npy"\ntheta = "theta.npy"\nphi = "phi.npy"\nradius = 3\n' > "$tmp/key.toml"
refuse "grid.radius: unknown key" "$tmp/key.toml" "$tmp/shell_0.npy"
printf '[grid]\nkind = "cubed-sphere"\n' > "$tmp/kind.toml"
refuse "grid.kind:" "$tmp/kind.toml" "$tmp/shell_0.npy"
printf '[grid]\nkind = "spherical"\nr = "missing.npy"\ntheta = "theta.npy"\nphi = "phi.npy"\n' > "$tmp/missing.toml"
refuse "missing.npy" "$tmp/missing.toml" "$tmp/shell_0.npy"
# Memory (issue 44, point 3): the grid stage and the march's corner copies are in the estimate (an
# 8x200x400 shell on its default 400^3 cover peaked at 2.5 GB, estimated at 348 MB and admitted under
# 400 MB); a 1024-point cover is refused by the estimate, not by a bare "out of memory"; a huge
# coordinate file is refused before it is read.
/usr/bin/python3 - "$tmp" <<'PY'
import sys, numpy as np
d = sys.argv[1]
np.save(f"{d}/big_r.npy", np.linspace(0.5, 1.0, 8))
np.save(f"{d}/big_theta.npy", np.linspace(0.01, np.pi - 0.01, 200))
np.save(f"{d}/big_phi.npy", np.linspace(-np.pi, np.pi, 400, endpoint=False))
np.save(f"{d}/big_vol.npy", np.zeros((400, 200, 8), np.float32))
# A coordinate file whose header claims 400 million values, sparse on disk (3.2 GB apparent).
header = b"\x93NUMPY\x01\x00" + (lambda h: len(h).to_bytes(2, "little") + h)(
    b"{'descr': '<f8', 'fortran_order': False, 'shape': (400000000,), }".ljust(118) + b"\n")
with open(f"{d}/sparse_r.npy", "wb") as f:
    f.write(header)
    f.truncate(len(header) + 8 * 400000000)
PY
printf '[grid]\nkind = "spherical"\nr = "big_r.npy"\ntheta = "big_theta.npy"\nphi = "big_phi.npy"\n' > "$tmp/big.toml"
PANOPTES_MEMORY_LIMIT=400M refuse "grid stage: resampling plan" "$tmp/big.toml" "$tmp/big_vol.npy"
PANOPTES_MEMORY_LIMIT=400M refuse "corner copies" "$tmp/big.toml" "$tmp/big_vol.npy"
printf '[grid]\nkind = "spherical"\nr = "big_r.npy"\ntheta = "big_theta.npy"\nphi = "big_phi.npy"\npoints = 1024\n' > "$tmp/p1024.toml"
PANOPTES_MEMORY_LIMIT=8G refuse "needs about" "$tmp/p1024.toml" "$tmp/big_vol.npy"
sed 's/"r.npy"/"sparse_r.npy"/' "$tmp/shell.toml" > "$tmp/sparse.toml"
start=$(date +%s%N)
refuse "coordinate file (at most 65535 values)" "$tmp/sparse.toml" "$tmp/shell_0.npy"
[ $(( ($(date +%s%N) - start) / 1000000 )) -lt 2000 ] || fail "the sparse coordinate file took over 2 s to refuse"
echo "render_grid.sh: OK"
