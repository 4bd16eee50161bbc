#!/usr/bin/env bash
# CLI test of `panoptes demo`: the embedded configuration is valid and runs (shortened here: fewer
# steps, cameras and pixels; the full demo takes minutes).
set -euo pipefail
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
export OMP_NUM_THREADS=1
"$bin" demo --help | grep "130 Yin-Yang" >/dev/null || { echo "FAIL: help"; exit 1; }
"$bin" demo --print-config > demo.toml
# The measured run time is stated once, in the configuration's "# Measured:" line; --help and the README
# repeat that line (the README verbatim).
measured=$(sed -n 's/^# Measured: //p' demo.toml)
[ -n "$measured" ] || { echo "FAIL: the demo configuration has no '# Measured:' line"; exit 1; }
"$bin" demo --help | tr -s ' \n' ' ' | grep -F "$measured" >/dev/null || { echo "FAIL: --help does not state: $measured"; exit 1; }
readme=$(dirname "$0")/../../../README.md
if [ -f "$readme" ]; then
  tr -s ' \n' ' ' < "$readme" | grep -F "$measured" >/dev/null || { echo "FAIL: README.md does not state: $measured"; exit 1; }
fi
grep -q 'spec = "yinyang"' demo.toml || { echo "FAIL: demo config is not the Yin-Yang rig"; exit 1; }
# examples/demo.toml is documented as the same text as the embedded configuration.
example=$(dirname "$0")/../../../examples/demo.toml
if [ -f "$example" ]; then
  diff -u "$example" demo.toml || { echo "FAIL: examples/demo.toml differs from panoptes demo --print-config"; exit 1; }
fi
sed -e 's/^steps = 480 .*/steps = 30/' -e 's/^every_steps = 10 .*/every_steps = 15/' \
    -e 's/^spec = "yinyang" .*/spec = "yinyang:2x3"/' -e 's/^width = 528/width = 48/' -e 's/^height = 512/height = 40/' \
    -e 's/^nx = 64/nx = 24/' -e 's/^ny = 128/ny = 48/' -e 's/^nz = 40/nz = 16/' -e 's/^h = 400.0/h = 1066.6667/' \
    -e 's/^pml_cells = 10/pml_cells = 4/' demo.toml > short.toml
# Every substitution must have applied (the demo configuration changed otherwise).
for line in 'steps = 30' 'every_steps = 15' 'spec = "yinyang:2x3"' 'width = 48' 'height = 40' 'nx = 24' 'ny = 48' \
            'nz = 16' 'h = 1066.6667' 'pml_cells = 4'; do
  grep -q "^$line" short.toml || { echo "FAIL: the shortened demo config lacks '$line'"; exit 1; }
done
"$bin" run short.toml --out short_db -q > run.log 2>&1 || { cat run.log; echo "FAIL: shortened demo"; exit 1; }
out=$("$bin" info --json short_db)
echo "$out" | grep -E '"status": *"complete"' >/dev/null || { echo "FAIL: not complete: $out"; exit 1; }
echo "$out" | grep -E '"frames": *2' >/dev/null || { echo "FAIL: expected 2 frames: $out"; exit 1; }
echo "demo.sh: ok"
