#!/usr/bin/env bash
# scripts/demo with a display (issue 34.1): the player opens on the live database and shows its first
# frame while the demo is still running. Under a virtual X server, with the demo's configuration shortened
# (fewer cameras and pixels, so it runs in seconds) and the player closing after its first shown frame:
# scripts/demo says "the player is closed; waiting for the demo to finish" only when the demo outlived the
# player. Skipped (passes) without xvfb-run or a window build.
set -euo pipefail
bin=$1
repo=$(cd "$(dirname "$0")/../../.." && pwd)
help=$("$bin" play --help)
if ! command -v xvfb-run >/dev/null || [[ $help != *--software* ]]; then
  echo "demo_script: skipped (no xvfb-run or no window player)"
  exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1
# 40 snapshots of 12 cameras x 3 tasks at 96x92: the demo's rig shape, windows and tasks, in seconds.
"$bin" demo --print-config |
  sed -e 's/^steps = 480 .*/steps = 200/' -e 's/^every_steps = 10 .*/every_steps = 5/' \
      -e 's/^spec = "yinyang" .*/spec = "yinyang:2x3"/' -e 's/^width = [0-9]*/width = 96/' -e 's/^height = [0-9]*/height = 92/' \
      > "$tmp/short.toml"
for line in 'steps = 200' 'every_steps = 5' 'spec = "yinyang:2x3"' 'width = 96' 'height = 92'; do
  grep -q "^$line" "$tmp/short.toml" || { echo "FAIL: the shortened demo config lacks '$line'"; exit 1; }
done
status=0
PANOPTES_BIN=$bin DEMO_CONFIG=$tmp/short.toml OUT=$tmp/db \
  PLAY_ARGS="--software --width 320 --height 320 --max-frames 1 --screenshot-on-exit $tmp/first.png" \
  timeout 600 xvfb-run -a -s "-screen 0 640x480x24" "$repo/scripts/demo" > "$tmp/log" 2>&1 || status=$?
[ "$status" = 0 ] || { cat "$tmp/log"; echo "FAIL: scripts/demo exited with $status"; exit 1; }
grep -q "opening the player on $tmp/db while the demo goes on" "$tmp/log" || { cat "$tmp/log"; echo "FAIL: no player"; exit 1; }
[ -s "$tmp/first.png" ] || { cat "$tmp/log"; echo "FAIL: the player wrote no first frame"; exit 1; }
grep -q "the player is closed; waiting for the demo to finish" "$tmp/log" ||
  { cat "$tmp/log"; echo "FAIL: the player's first frame came only after the demo had ended"; exit 1; }
"$bin" info --json "$tmp/db" | grep -E '"status": *"complete"' >/dev/null || { echo "FAIL: database not complete"; exit 1; }
echo "demo_script: ok"
