#!/usr/bin/env bash
# `panoptes render`: VTK ASCII/BINARY and NumPy inputs, a time series from a glob, the database it
# writes (cameras x tasks streams, frames), quiet when not a terminal, and clear errors.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

fail() { echo "render.sh: $*" >&2; exit 1; }

# A 12x10x8 VTK ASCII volume: distance from the centre.
{
  echo "# vtk DataFile Version 3.0"
  echo "sphere"
  echo "ASCII"
  echo "DATASET STRUCTURED_POINTS"
  echo "DIMENSIONS 12 10 8"
  echo "ORIGIN -5.5 -4.5 -3.5"
  echo "SPACING 1 1 1"
  echo "POINT_DATA 960"
  echo "SCALARS d float 1"
  echo "LOOKUP_TABLE default"
  awk 'BEGIN { for (k = 0; k < 8; k++) for (j = 0; j < 10; j++) for (i = 0; i < 12; i++)
               printf "%.4f\n", sqrt((i-5.5)^2 + (j-4.5)^2 + (k-3.5)^2) }'
} > "$tmp/sphere.vtk"

"$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:4 --task volume:hot --task iso:3 --task iso:2 \
  --task slice:z:0.5 --size 48x40 --out "$tmp/db" > "$tmp/out.txt" 2> "$tmp/err.txt"
grep -q "4 cameras x 4 tasks = 16 streams, 1 frames of 48x40" "$tmp/out.txt" || fail "unexpected summary: $(cat "$tmp/out.txt")"
# Progress while it works, also when stderr is a log file (one line per tenth), none with -q.
grep -q "render: 16/16 images (100%)" "$tmp/err.txt" || fail "no progress lines on a non-terminal: $(cat "$tmp/err.txt")"
"$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:2 --size 32x24 -q --out "$tmp/quiet" > /dev/null 2> "$tmp/err.txt"
[ ! -s "$tmp/err.txt" ] || fail "progress output despite -q: $(cat "$tmp/err.txt")"
[ -f "$tmp/db/panoptes.json" ] || fail "no manifest"
[ "$(find "$tmp/db" -name '*.mp4' | wc -l)" = 16 ] || fail "expected 16 movies"
grep -q '"isovalue"' "$tmp/db/panoptes.json" || fail "no isovalue axis in the manifest"
grep -q '"complete"' "$tmp/db/panoptes.json" || fail "database not finalized"

# Refuses to overwrite without --overwrite, accepts with it.
if "$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:4 --size 48x40 --out "$tmp/db" 2> "$tmp/err.txt"; then
  fail "overwrote an existing database"
fi
grep -q "panoptes: error:" "$tmp/err.txt" || fail "no error line"
# Issue 44: the advice names this command's option, not a TOML key render never reads.
grep -q -- "add --overwrite" "$tmp/err.txt" || fail "the refusal does not name --overwrite: $(cat "$tmp/err.txt")"
grep -q "\[output\]" "$tmp/err.txt" && fail "render's refusal names a TOML key: $(cat "$tmp/err.txt")"
"$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:4 --size 48x40 --out "$tmp/db" --overwrite > /dev/null
# One value per --task: a volume after --task is still the input.
"$panoptes" render --task iso:3 "$tmp/sphere.vtk" --rig fibonacci:2 --size 32x32 --out "$tmp/db2" > "$tmp/out.txt"
grep -q "2 cameras x 1 tasks" "$tmp/out.txt" || fail "--task took the volume as a task: $(cat "$tmp/out.txt")"

if command -v python3 > /dev/null; then
  # NumPy files without numpy: header + little-endian float32/float64 data; a BINARY VTK (big-endian).
  python3 - "$tmp" <<'EOF'
import struct, sys, math
tmp = sys.argv[1]
def npy(path, shape, values, descr="<f4", fmt="<f"):
    header = "{'descr': '%s', 'fortran_order': False, 'shape': %s, }" % (descr, str(tuple(shape)))
    header += " " * (63 - (10 + len(header)) % 64) + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode())
        f.write(b"".join(struct.pack(fmt, v) for v in values))
nz, ny, nx = 8, 10, 12
for t in range(3):
    vals = [math.sin(0.5 * i + 0.3 * j + 0.2 * k + t) for k in range(nz) for j in range(ny) for i in range(nx)]
    npy(f"{tmp}/series_{t}.npy", (nz, ny, nx), vals, "<f8", "<d")
npy(f"{tmp}/flat.npy", (ny, nx), [0.0] * (nx * ny))
npy(f"{tmp}/ints.npy", (nz, ny, nx), [0] * (nx * ny * nz), "<i4", "<i")
npy(f"{tmp}/other.npy", (nz, ny, nx + 1), [0.0] * ((nx + 1) * ny * nz))
npy(f"{tmp}/nan.npy", (nz, ny, nx), [float("nan")] * (nx * ny * nz))
with open(f"{tmp}/bin.vtk", "wb") as f:
    f.write(b"# vtk DataFile Version 3.0\nbinary\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 12 10 8\n"
            b"ORIGIN 0 0 0\nSPACING 0.5 0.5 0.5\nPOINT_DATA 960\nSCALARS v double\nLOOKUP_TABLE default\n")
    f.write(b"".join(struct.pack(">d", math.cos(0.4 * i) * j / 10) for k in range(8) for j in range(10) for i in range(12)))
EOF
  "$panoptes" render "$tmp/series_*.npy" --rig fibonacci:3 --task volume:diverging --size 32x32 --out "$tmp/series" > "$tmp/out.txt"
  grep -q "3 cameras x 1 tasks = 3 streams, 3 frames of 32x32" "$tmp/out.txt" || fail "series: $(cat "$tmp/out.txt")"
  grep -q '"frames_written": 3' "$tmp/series/panoptes.json" || fail "series: frames_written is not 3"
  "$panoptes" render "$tmp/bin.vtk" --rig fibonacci:2 --task volume:p-wave:0:1 --size 32x32 --out "$tmp/bin" > /dev/null

  expect_error() {  # expect_error PATTERN ARGS...: fails with exit 1 and one error line matching PATTERN
    local pattern=$1; shift
    if "$panoptes" render "$@" 2> "$tmp/err.txt" > /dev/null; then fail "accepted: $*"; fi
    grep -q "panoptes: error:.*$pattern" "$tmp/err.txt" || fail "for '$*' expected /$pattern/, got: $(cat "$tmp/err.txt")"
  }
  expect_error "3-D volume" "$tmp/flat.npy" --rig fibonacci:2 --out "$tmp/e1"
  expect_error "float32" "$tmp/ints.npy" --rig fibonacci:2 --out "$tmp/e2"
  expect_error "expected 12x10x8" "$tmp/series_0.npy" "$tmp/other.npy" --rig fibonacci:2 --out "$tmp/e3"

  # An all-NaN volume is rendered (empty frames) but not without a word.
  "$panoptes" render "$tmp/nan.npy" --rig fibonacci:2 --size 32x24 -q --out "$tmp/nan" > /dev/null 2> "$tmp/err.txt"
  grep -q "panoptes: warning: .*nan.npy: none of its 960 values is a finite number" "$tmp/err.txt" ||
    fail "no warning for an all-NaN volume: $(cat "$tmp/err.txt")"
fi

# Provenance: the recorded command line holds every option that changes pixels, and running it again
# reproduces the same frames.
"$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:3 --task volume:hot:0:4 --size 40x32 --sample-distance 0.7 \
  --no-outline --percentile 0.99 --spacing 1,1,2 --origin 0,0,-3 --background 0.2,0,0.1 --crf 30 --up-axis z_down \
  -q --out "$tmp/prov" > /dev/null
line=$("$panoptes" info --json "$tmp/prov" | sed -n 's/.*"command_line": *"\(.*\)",*$/\1/p')
for opt in --sample-distance --no-outline --percentile --spacing --origin --background --crf --up-axis --size --task --rig; do
  case "$line" in *"$opt"*) ;; *) fail "recorded command line lacks $opt: $line" ;; esac
done
again=${line/--out $tmp\/prov/--out $tmp/prov2}
[ "$again" != "$line" ] || fail "cannot find --out in the recorded line: $line"
eval "\"\$panoptes\"${again#panoptes} -q" > /dev/null || fail "the recorded line does not run: $again"
printf 't=0 camera=1\nt=0.04 camera=2\n' > "$tmp/cams.txt"
"$panoptes" play "$tmp/prov" --headless --script "$tmp/cams.txt" --paused --frames-out "$tmp/f1" > /dev/null
"$panoptes" play "$tmp/prov2" --headless --script "$tmp/cams.txt" --paused --frames-out "$tmp/f2" > /dev/null
for f in "$tmp"/f1/*.png; do cmp -s "$f" "$tmp/f2/$(basename "$f")" || fail "frame $(basename "$f") differs after re-running the recorded line"; done
# ... and the options did matter: a default render of the same volume looks different.
"$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:3 --task volume:hot:0:4 --size 40x32 -q --out "$tmp/plain" > /dev/null
"$panoptes" play "$tmp/plain" --headless --script "$tmp/cams.txt" --paused --frames-out "$tmp/f3" > /dev/null
! cmp -s "$tmp/f1/frame_000000.png" "$tmp/f3/frame_000000.png" || fail "non-default options changed nothing"

echo "not a volume" > "$tmp/vol.txt"
if "$panoptes" render "$tmp/vol.txt" --out "$tmp/e4" 2> "$tmp/err.txt"; then fail "accepted a .txt file"; fi
grep -q "unsupported volume format" "$tmp/err.txt" || fail "unclear error for .txt: $(cat "$tmp/err.txt")"
if "$panoptes" render "$tmp/sphere.vtk" --task volume:nope --out "$tmp/e5" 2> "$tmp/err.txt"; then fail "accepted a bad preset"; fi
grep -q "p-wave" "$tmp/err.txt" || fail "bad preset error does not list presets: $(cat "$tmp/err.txt")"
if "$panoptes" render "$tmp/sphere.vtk" --task slice:w:0.5 --out "$tmp/e6" 2> "$tmp/err.txt"; then fail "accepted axis w"; fi
# Issue 43: every kind is a --task word; the help and the usage error list them from one list.
"$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:2 --task mip:hot --size 32x24 -q --out "$tmp/mip" > /dev/null
grep -q '"method": *"mip"' "$tmp/mip/panoptes.json" || fail "no mip task in the manifest"
"$panoptes" render --help > "$tmp/help.txt"  # to a file: grep -q in a pipe would cut it off (pipefail)
grep -q "mip:PRESET\[:LO:HI\]" "$tmp/help.txt" || fail "render --help does not list mip"
if "$panoptes" render "$tmp/sphere.vtk" --task cube:1 --out "$tmp/e11" 2> "$tmp/err.txt"; then fail "accepted kind cube"; fi
grep -q "or mip:PRESET" "$tmp/err.txt" || fail "the kind error does not list mip: $(cat "$tmp/err.txt")"
if "$panoptes" render "$tmp/missing.npy" --out "$tmp/e7" 2> "$tmp/err.txt"; then fail "accepted a missing file"; fi
grep -q "missing.npy" "$tmp/err.txt" || fail "missing-file error does not name the file"
# Issue 15: memory and open files are checked before the database exists; a device is not a volume.
if PANOPTES_MEMORY_LIMIT=1M "$panoptes" render "$tmp/sphere.vtk" --rig fibonacci:4 --size 32x32 --out "$tmp/e8" 2> "$tmp/err.txt"; then
  fail "accepted with 1 MB"
fi
grep -q "this render needs about" "$tmp/err.txt" && [ ! -e "$tmp/e8" ] || fail "memory: $(cat "$tmp/err.txt")"
if "$panoptes" render /dev/zero.npy --out "$tmp/e9" 2> "$tmp/err.txt"; then fail "accepted /dev/zero.npy"; fi
ln -s /dev/zero "$tmp/zero.npy"
if "$panoptes" render "$tmp/zero.npy" --out "$tmp/e9" 2> "$tmp/err.txt"; then fail "accepted /dev/zero"; fi
grep -q "is a character device" "$tmp/err.txt" || fail "device: $(cat "$tmp/err.txt")"
if "$panoptes" render "$tmp/sphere.vtk" --size 20000x20 --out "$tmp/e10" 2> "$tmp/err.txt"; then fail "accepted 20000 pixels"; fi
echo "render: ok"
