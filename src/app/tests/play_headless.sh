#!/usr/bin/env bash
# `panoptes play --headless`: a scripted run writes one PNG per displayed tick and statistics whose
# displayed list follows the script (camera/task/frame after each command), broken streams show
# placeholders without stopping playback, and bad input fails with one clear line.
set -euo pipefail
panoptes=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

"$panoptes" synth-db db --cameras 6 --tasks 3 --frames 20 --size 64x64 >/dev/null
cat > s.txt <<'SCRIPT'
# rotate right, next task, seek, rotate back
t=0.2 key=Right
t=0.4 key=Tab
t=0.5 seek=3
t=0.8 key=Left
SCRIPT
"$panoptes" play db --headless --script s.txt --speed 1 --frames-out frames --stats stats.json > out.txt
grep -q "played 25 frames (0 placeholders)" out.txt || { cat out.txt; echo "unexpected summary"; exit 1; }
[ "$(ls frames | wc -l)" -eq 25 ] || { echo "expected 25 PNGs"; exit 1; }
[ -s frames/frame_000000.png ] && [ -s frames/frame_000024.png ]

# selection per tick from the statistics (camera task frame)
sel() { jq -r ".displayed[$1] | \"\(.camera) \(.task) \(.frame)\"" stats.json; }
[ "$(sel 0)" = "0 0 0" ] || { echo "tick 0: $(sel 0)"; exit 1; }
[ "$(sel 5)" = "0 0 5" ] || { echo "tick 5: $(sel 5)"; exit 1; }
[ "$(sel 6)" = "1 0 6" ] || { echo "tick 6 (after Right): $(sel 6)"; exit 1; }
[ "$(sel 12)" = "1 1 12" ] || { echo "tick 12 (after Tab): $(sel 12)"; exit 1; }
[ "$(sel 15)" = "1 1 3" ] || { echo "tick 15 (after seek=3): $(sel 15)"; exit 1; }
[ "$(sel 24)" = "0 1 12" ] || { echo "tick 24 (after Left): $(sel 24)"; exit 1; }
[ "$(jq '.switch_latency.count' stats.json)" = 3 ] || { echo "expected 3 switches"; exit 1; }
jq -e '.decode_time.count > 0 and .cache.hits >= 0' stats.json >/dev/null

# A missing movie: placeholder while camera 1 is shown, playback continues.
rm db/movies/c1/t0.mp4
"$panoptes" play db --headless --script s.txt --speed 1 --stats stats2.json > out2.txt
grep -q "played 25 frames (6 placeholders)" out2.txt || { cat out2.txt; echo "expected 6 placeholders"; exit 1; }
[ "$(jq -r '.displayed[6].status' stats2.json)" = missing ]
[ "$(jq -r '.displayed[13].frame' stats2.json)" = 13 ]

# Prefetch off still shows the same frames.
"$panoptes" play db --headless --script s.txt --speed 1 --stats stats3.json --no-prefetch >/dev/null
[ "$(jq -c '[.displayed[] | [.camera,.task,.frame]]' stats2.json)" = "$(jq -c '[.displayed[] | [.camera,.task,.frame]]' stats3.json)" ]
[ "$(jq '.decodes.prefetch' stats3.json)" = 0 ]

# Clear errors.
expect_error() {  # expect_error FRAGMENT CMD...
  local fragment=$1; shift
  if "$@" > err.txt 2>&1; then echo "accepted: $*"; exit 1; fi
  grep -q -- "$fragment" err.txt || { cat err.txt; echo "missing '$fragment'"; exit 1; }
}
expect_error "no such database directory" "$panoptes" play nowhere --headless
mkdir notdb
expect_error "not a Panoptes database" "$panoptes" play notdb --headless
printf 't=0.1 key=Nope\n' > bad.txt
expect_error "bad.txt:1: unknown key \"Nope\"" "$panoptes" play db --headless --script bad.txt
expect_error "camera 9 out of range" "$panoptes" play db --headless --camera 9
# A script naming a camera or task that does not exist is an error, not silently ignored.
printf 't=0 key=Right\nt=0.1 camera=999\n' > cam.txt
expect_error "script line 2: camera 999 does not exist; the database has cameras 0..5" "$panoptes" play db --headless --script cam.txt
printf 't=0 task=nosuch\n' > task.txt
expect_error "no task named \"nosuch\"" "$panoptes" play db --headless --script task.txt
# A command-line mistake is one line in the house style and status 1, like every other error.
set +e
"$panoptes" play > err.txt 2>&1
status=$?
set -e
[ "$status" = 1 ] || { cat err.txt; echo "panoptes play without arguments exited $status; expected 1"; exit 1; }
[ "$(wc -l < err.txt)" = 1 ] || { cat err.txt; echo "expected one line"; exit 1; }
grep -q "^panoptes: error: .*db is required.*panoptes play --help" err.txt || { cat err.txt; echo "not the house style"; exit 1; }
echo "play_headless: ok"
