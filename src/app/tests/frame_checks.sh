#!/usr/bin/env bash
# Frames never lie (issue #31, rows 5 and 6): `info --decode` reports a garbled first frame, a movie
# in another stream's place and a re-ordered movie as damaged, never "all readable".
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "frame_checks: $*"; exit 1; }
py=/usr/bin/python3

"$panoptes" synth-db "$tmp/db" --cameras 3 --tasks 1 --frames 4 --size 48x32 --gop 1 >/dev/null
"$panoptes" info "$tmp/db" --decode > "$tmp/out" || { cat "$tmp/out"; fail "a fresh database is not all readable"; }
grep -q "^checks     every frame" "$tmp/out" || { cat "$tmp/out"; fail "info does not say how frames are checked"; }

# Row 5: one byte of the first frame's picture (the first mdat) flipped.
"$py" - "$tmp/db/movies/c0/t0.mp4" <<'PY'
import sys
p = sys.argv[1]; b = bytearray(open(p, 'rb').read())
i = b.find(b'mdat'); size = int.from_bytes(b[i - 4:i], 'big')
b[i - 4 + size - 6] ^= 0x10
open(p, 'wb').write(b)
PY
# Row 6: camera 2's movie replaced by camera 1's (a foreign movie), and camera 1's first tfdt made late.
cp "$tmp/db/movies/c1/t0.mp4" "$tmp/db/movies/c2/t0.mp4"
"$py" - "$tmp/db/movies/c1/t0.mp4" <<'PY'
import sys
p = sys.argv[1]; b = bytearray(open(p, 'rb').read())
i = b.find(b'tfdt'); at = i + 8 + (4 if b[i + 4] == 1 else 0)
b[at:at + 4] = (1 << 24).to_bytes(4, 'big')
open(p, 'wb').write(b)
PY
set +e
"$panoptes" info "$tmp/db" --decode --json > "$tmp/out"
status=$?
set -e
[ "$status" = 2 ] || { cat "$tmp/out"; fail "info --decode exit status $status, expected 2"; }
"$py" - "$tmp/out" <<'PY' || { cat "$tmp/out"; exit 1; }
import json, sys
problems = {p['camera']: p for p in json.load(open(sys.argv[1]))['check']['problems']}
assert sorted(problems) == [0, 1, 2], problems
assert problems[0]['kind'] == 'damaged' and problems[0]['damaged_frames'] == [0], problems[0]
assert problems[1]['kind'] == 'damaged' and problems[1]['damaged_frames'] == [0, 1, 2, 3], problems[1]
assert 'shown at index' in problems[1]['message'] or 'timestamp' in problems[1]['message'], problems[1]
assert problems[2]['kind'] == 'damaged' and 'another movie' in problems[2]['message'], problems[2]
PY

# The web server's index names the same damaged frames, so the browser shows its placeholder.
"$panoptes" serve "$tmp/db" --port 0 > "$tmp/log" 2>&1 &
server=$!
trap 'kill "$server" 2>/dev/null || true; rm -rf "$tmp"' EXIT
port=""
for _ in $(seq 100); do
  port=$(sed -n 's|^serving .* at http://127.0.0.1:\([0-9]*\)/.*$|\1|p' "$tmp/log")
  [ -n "$port" ] && break
  sleep 0.1
done
[ -n "$port" ] || { cat "$tmp/log"; fail "serve printed no address"; }
"$py" - "$port" <<'PY' || fail "serve's fragment indexes do not name the damaged frames"
import json, sys, urllib.request
port = sys.argv[1]
def index(c):
    return json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/api/index/{c}/0.json", timeout=20))
assert index(0).get("damaged_frames") == [0], index(0)
assert index(1).get("damaged_frames") == [0, 1, 2, 3], index(1)
assert index(2).get("damaged_frames") == [0, 1, 2, 3], index(2)
PY
kill "$server" 2>/dev/null || true

# Issue 44, point 1: a flipped bit in the avcC's PPS (outside every frame's CRC) changed every frame while
# all read as ok at 11-13 dB; now every frame is damaged, naming the parameter sets. And a database
# written before frame checks is said to be unverified, not "all readable".
"$panoptes" synth-db "$tmp/pps" --cameras 2 --tasks 1 --frames 3 --size 48x32 --gop 1 >/dev/null
"$py" - "$tmp/pps/movies/c0/t0.mp4" <<'PY'
import sys
p = sys.argv[1]; b = bytearray(open(p, 'rb').read())
i = b.find(b'avcC') + 4; at = i + 5
n_sps = b[at] & 0x1f; at += 1
for _ in range(n_sps): at += 2 + int.from_bytes(b[at:at + 2], 'big')
at += 1  # number of PPS
pps_len = int.from_bytes(b[at:at + 2], 'big'); at += 2
b[at + pps_len - 1] ^= 0x02  # the PPS's last byte
open(p, 'wb').write(b)
PY
set +e
"$panoptes" info "$tmp/pps" --decode --json > "$tmp/pps.json"
status=$?
set -e
[ "$status" = 2 ] || { cat "$tmp/pps.json"; fail "a damaged PPS: info --decode exit status $status, expected 2"; }
"$py" - "$tmp/pps.json" <<'PY' || { cat "$tmp/pps.json"; exit 1; }
import json, sys
j = json.load(open(sys.argv[1]))
assert j['frames_verified'] == 'all', j['frames_verified']
problems = j['check']['problems']
assert len(problems) == 1 and problems[0]['camera'] == 0 and problems[0]['damaged_frames'] == [0, 1, 2], problems
assert 'parameter sets' in problems[0]['message'], problems[0]
PY
"$py" - "$tmp/pps/panoptes.json" <<'PY'
import json, sys
p = sys.argv[1]; j = json.load(open(p)); del j['frame_checks']; open(p, 'w').write(json.dumps(j))
PY
rm -f "$tmp/pps/movies/c0/t0.mp4" && cp "$tmp/pps/movies/c1/t0.mp4" "$tmp/pps/movies/c0/t0.mp4"
"$panoptes" info "$tmp/pps" --decode > "$tmp/old.txt" || { cat "$tmp/old.txt"; fail "an old database"; }
grep -q "all readable, frames unverified" "$tmp/old.txt" || { cat "$tmp/old.txt"; fail "an old database is not said to be unverified"; }
grep -q "^checks     UNVERIFIED" "$tmp/old.txt" || { cat "$tmp/old.txt"; fail "the checks line of an old database"; }
echo "frame_checks: ok"
