#!/usr/bin/env bash
# CLI test (issue 34): the demo's first frame shows the source, not a box full of orange haze. The demo's
# own configuration runs its first two snapshots (t = 0.27 s and 0.54 s) with 6 of the 130 cameras; the
# p+s and p-wave frames of the first snapshot must be lit about as sparsely as the second's (the relative
# windows' reference used to fall into the numerical precursor at the first snapshot: 24 % of the pixels
# lit at frame 0 against 0.4 % at frame 1).
set -euo pipefail
bin=$1
share=$(dirname "$bin")/png_colour_share
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
export OMP_NUM_THREADS=2
"$bin" demo --print-config |
  sed -e 's/^steps = 480 .*/steps = 20/' -e 's/^spec = "yinyang" .*/spec = "yinyang:1x3"/' > early.toml
for line in 'steps = 20' 'every_steps = 10' 'spec = "yinyang:1x3"'; do
  grep -q "^$line" early.toml || { echo "FAIL: the early demo config lacks '$line'"; exit 1; }
done
"$bin" run early.toml --out db -q > run.log 2>&1 || { cat run.log; echo "FAIL: early demo"; exit 1; }
for frame in 0 1; do
  printf 't=0 seek=%d\n' "$frame" > s.txt
  for c in 1 2 3 4 5; do printf 't=0.%d camera=%d\n' "$c" "$c" >> s.txt; done
  for task in p+s p-wave; do
    "$bin" play db --headless --script s.txt --task "$task" --paused --frames-out "f$frame-$task" > /dev/null
  done
done
pixels=$((6 * 400 * 390))
for task in p+s p-wave; do
  read -r _ lit0 _ < <("$share" "f0-$task"/*.png)
  read -r _ lit1 _ < <("$share" "f1-$task"/*.png)
  echo "$task: frame 0 $lit0 lit pixels, frame 1 $lit1 (of $pixels)"
  [ "$lit0" -gt 0 ] || { echo "FAIL: $task frame 0 is empty"; exit 1; }
  # The source grows: frame 0 lit no more than frame 1 (plus a margin), and well under 2 % of the pixels.
  [ "$lit0" -le $((lit1 + lit1 / 4)) ] && [ "$lit0" -lt $((pixels / 50)) ] ||
    { echo "FAIL: $task frame 0 is lit on $lit0 pixels against $lit1 at frame 1: haze"; exit 1; }
done
echo "demo_first_frame.sh: ok"
