#!/usr/bin/env bash
# CLI test: both wave types are clearly visible in the demo. The demo's own configuration (physics,
# windows, image size, camera framing) runs up to mid-run — steps 240 of 480 — with 6 of the 130
# cameras and two snapshots (steps 120 and 240) so it takes seconds; then the p+s task's mid-run frames
# must be at least 15 % orange (p-waves) among their coloured pixels, and the p-wave task not empty.
set -euo pipefail
bin=$1
share=$(dirname "$bin")/png_colour_share
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
export OMP_NUM_THREADS=2
"$bin" demo --print-config |
  sed -e 's/^steps = 480 .*/steps = 240/' -e 's/^every_steps = 12 .*/every_steps = 120/' \
      -e 's/^spec = "yinyang" .*/spec = "yinyang:1x3"/' > mid.toml
for line in 'steps = 240' 'every_steps = 120' 'spec = "yinyang:1x3"'; do
  grep -q "^$line" mid.toml || { echo "FAIL: the mid-run demo config lacks '$line'"; exit 1; }
done
"$bin" run mid.toml --out db -q > run.log 2>&1 || { cat run.log; echo "FAIL: mid-run demo"; exit 1; }
# Frame 1 (step 240) of every camera, p+s task and p-wave task.
printf 't=0 seek=1\n' > s.txt
for c in 1 2 3 4 5; do printf 't=%s camera=%d\n' "0.$c" "$c" >> s.txt; done
"$bin" play db --headless --script s.txt --task p+s --paused --frames-out ps > /dev/null
"$bin" play db --headless --script s.txt --task p-wave --paused --frames-out p > /dev/null
read -r _ coloured _ orange _ green _ share_ps < <("$share" ps/*.png)
read -r _ p_coloured _ _ _ _ _ _ < <("$share" p/*.png)
echo "p+s at mid-run: $coloured coloured pixels, $orange orange, $green green (orange share $share_ps); p-wave task: $p_coloured coloured"
awk -v s="$share_ps" 'BEGIN { exit !(s >= 0.15) }' || { echo "FAIL: orange (p) is only $share_ps of the p+s task's coloured pixels; expected >= 0.15"; exit 1; }
[ "$coloured" -gt 20000 ] || { echo "FAIL: the p+s frames are nearly empty ($coloured coloured pixels in 6 frames)"; exit 1; }
[ "$p_coloured" -gt 20000 ] || { echo "FAIL: the p-wave task is nearly empty ($p_coloured coloured pixels in 6 frames)"; exit 1; }
echo "demo_colours.sh: ok"
