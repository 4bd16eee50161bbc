#!/usr/bin/env bash
# CLI test of `panoptes demo`: the embedded configuration is valid and runs (shortened here: fewer
# steps, cameras and pixels; the full demo takes minutes).
set -euo pipefail
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
export OMP_NUM_THREADS=1
"$bin" demo --help | grep -q "130 Yin-Yang" || { echo "FAIL: help"; exit 1; }
"$bin" demo --print-config > demo.toml
grep -q 'spec = "yinyang"' demo.toml || { echo "FAIL: demo config is not the Yin-Yang rig"; exit 1; }
sed -e 's/^steps = 360 .*/steps = 30/' -e 's/^every_steps = 15 .*/every_steps = 15/' \
    -e 's/^spec = "yinyang" .*/spec = "yinyang:2x3"/' -e 's/^width = 256/width = 48/' -e 's/^height = 224/height = 40/' \
    -e 's/^nx = 48/nx = 24/' -e 's/^ny = 96/ny = 48/' -e 's/^nz = 32/nz = 16/' -e 's/^h = 533.3333/h = 1066.6667/' \
    -e 's/^pml_cells = 8/pml_cells = 4/' demo.toml > short.toml
"$bin" run short.toml --out short_db -q > run.log 2>&1 || { cat run.log; echo "FAIL: shortened demo"; exit 1; }
out=$("$bin" info --json short_db)
echo "$out" | grep -Eq '"status": *"complete"' || { echo "FAIL: not complete: $out"; exit 1; }
echo "$out" | grep -Eq '"frames": *2' || { echo "FAIL: expected 2 frames: $out"; exit 1; }
echo "demo.sh: ok"
