#!/usr/bin/env bash
# `panoptes export-path`: the shown sequence of a script becomes one MP4 with one frame per tick.
set -euo pipefail
panoptes=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

"$panoptes" synth-db db --cameras 4 --tasks 2 --frames 12 --size 64x64 >/dev/null
printf 't=0.1 key=Right\nt=0.3 key=Tab\nt=0.5 key=Right\n' > s.txt
"$panoptes" export-path db --script s.txt --out path.mp4 | grep "wrote path.mp4: 16 frames" >/dev/null
frames=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames,width,height \
         -of csv=p=0 path.mp4)
[ "$frames" = "64,64,16" ] || { echo "ffprobe says: $frames"; exit 1; }
# The movie plays at the player's rate: with playback_fps 10 (as the demo has; the movies are 30 fps) the
# 0.5 s script plus one frame period is 6 frames lasting 0.6 s, not 6 frames at 30 fps (0.2 s).
jq '.playback_fps = 10' db/panoptes.json > m.json && mv m.json db/panoptes.json
"$panoptes" export-path db --script s.txt --out slow.mp4 | grep "wrote slow.mp4: 6 frames at 10 fps = 0.6 s" >/dev/null
duration=$(ffprobe -v error -select_streams v:0 -show_entries stream=duration -of csv=p=0 slow.mp4)
awk -v d="$duration" 'BEGIN { exit !(d > 0.55 && d < 0.65) }' || { echo "slow.mp4 lasts $duration s, expected 0.6"; exit 1; }
# A 5 s path is a 5 s movie at the player's rate (issue 34), as ffprobe reads the file.
printf 't=0.1 key=Right\nt=2.0 key=Tab\nt=4.5 key=Right\n' > five.txt
"$panoptes" export-path db --script five.txt --duration 5 --out five.mp4 | grep "wrote five.mp4: 50 frames at 10 fps = 5.0 s" >/dev/null
probe=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=r_frame_rate,nb_read_frames,duration \
        -of csv=p=0 five.mp4)
awk -F, -v p="$probe" 'BEGIN { split(p, f, ","); exit !(f[1] == "10/1" && f[2] > 4.99 && f[2] < 5.01 && f[3] == 50) }' ||
  { echo "five.mp4: ffprobe says $probe, expected 10/1,5.0,50"; exit 1; }
if "$panoptes" export-path db --script s.txt --out /nonexistent/dir/x.mp4 2>err.txt; then
  echo "unwritable output accepted"; exit 1
fi
grep -q "output directory does not exist" err.txt
echo "export_path: ok"
