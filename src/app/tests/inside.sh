#!/usr/bin/env bash
# Issue 14 end to end: `panoptes render` with a lattice rig and 360-degree frames, the manifest's additive
# rig parameters, a path rig, headless walking/looking, export-path's cut-out and clear errors.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "inside.sh: $*" >&2; exit 1; }

# A 12x10x8 VTK ASCII volume: distance from the centre.
{
  echo "# vtk DataFile Version 3.0"; echo "sphere"; echo "ASCII"; echo "DATASET STRUCTURED_POINTS"
  echo "DIMENSIONS 12 10 8"; echo "ORIGIN -5.5 -4.5 -3.5"; echo "SPACING 1 1 1"; echo "POINT_DATA 960"
  echo "SCALARS d float 1"; echo "LOOKUP_TABLE default"
  awk 'BEGIN { for (k = 0; k < 8; k++) for (j = 0; j < 10; j++) for (i = 0; i < 12; i++)
               printf "%.4f\n", sqrt((i-5.5)^2 + (j-4.5)^2 + (k-3.5)^2) }'
} > "$tmp/sphere.vtk"

"$panoptes" render "$tmp/sphere.vtk" --rig lattice:2x2x2 --projection equirectangular --task volume:hot:0:6 \
  --size 64x32 -q --out "$tmp/db" > "$tmp/out.txt"
grep -q "8 cameras x 1 tasks = 8 streams, 1 frames of 64x32" "$tmp/out.txt" || fail "unexpected summary: $(cat "$tmp/out.txt")"
grep -Eq '"projection": ?"equirectangular"' "$tmp/db/panoptes.json" || fail "no projection in the manifest"
grep -q '"lattice"' "$tmp/db/panoptes.json" || fail "no lattice shape in the manifest"
grep -q -- "--projection equirectangular" "$tmp/db/panoptes.json" || fail "the recorded command line lacks --projection"

# Walk forward (+y), turn right and walk (+x), then up (+z): camera 0 -> 2 -> 3 -> 7.
printf 't=0.1 walk=forward\nt=0.2 look=90,0,90\nt=0.3 walk=forward\nt=0.4 walk=up\nt=0.5 end\n' > "$tmp/walk.txt"
"$panoptes" play "$tmp/db" --headless --script "$tmp/walk.txt" --stats "$tmp/stats.json" > /dev/null
last=$(/usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["displayed"][-1]["camera"], d["displayed"][-1]["look"][0])' "$tmp/stats.json")
[ "$last" = "7 90.0" ] || fail "after the walks: camera and yaw '$last', expected '7 90.0'"

# export-path writes the perspective cut-out at --view-size.
"$panoptes" export-path "$tmp/db" --script "$tmp/walk.txt" --view-size 96x64 --out "$tmp/walk.mp4" > /dev/null
[ -s "$tmp/walk.mp4" ] || fail "export-path wrote no movie"

# A path rig: 3 cameras along a polyline, graph in = next.
printf '# a flight\n-4 -3 0\n0 0 0\n4 3 1\n' > "$tmp/flight.txt"
"$panoptes" render "$tmp/sphere.vtk" --rig "path:$tmp/flight.txt" --size 32x32 -q --out "$tmp/path" > /dev/null
grep -Eq '"path": ?true' "$tmp/path/panoptes.json" || fail "no path flag in the manifest"

# Errors name the value and what was expected.
if "$panoptes" render "$tmp/sphere.vtk" --rig lattice:2x2 --size 32x32 --out "$tmp/bad" 2> "$tmp/err.txt"; then fail "lattice:2x2 accepted"; fi
grep -q "lattice:2x2" "$tmp/err.txt" || fail "error does not name the spec: $(cat "$tmp/err.txt")"
if "$panoptes" render "$tmp/sphere.vtk" --projection fisheye --out "$tmp/bad" 2> "$tmp/err.txt"; then fail "fisheye accepted"; fi
echo "inside.sh: ok"
