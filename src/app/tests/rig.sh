#!/usr/bin/env bash
# `panoptes rig`: statistics of the default rigs, JSON dump with a consistent graph, camera files,
# nearest-camera lookup, and clear errors for bad specs.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$panoptes" rig --help | grep "yinyang" >/dev/null

# The paper's rig: 130 cameras, nearest-neighbour angles 9.87..18 deg, strongly connected graph.
out=$("$panoptes" rig yinyang --extent 256,512,160)
echo "$out" | grep "^rig yinyang:5x13@3$" >/dev/null || { echo "$out"; echo "bad canonical spec"; exit 1; }
echo "$out" | grep "^cameras  *130 on 1 shell$" >/dev/null || { echo "$out"; echo "bad count"; exit 1; }
echo "$out" | grep "yang 65 yin 65" >/dev/null || { echo "$out"; echo "bad patches"; exit 1; }
echo "$out" | grep "nearest neighbour  *9.871 .. 18.000 deg" >/dev/null || { echo "$out"; echo "bad spacing"; exit 1; }
echo "$out" | grep "strongly connected" >/dev/null || { echo "$out"; echo "graph not connected"; exit 1; }
# Issue 34: opposite moves undo each other as the players press them, for every shipped sphere rig
# (the graph alone: Yin-Yang up then down 83.1 %).
echo "$out" | grep "^up then down  *returns for 100.0 % of cameras in the players (graph alone 83.1 %)$" >/dev/null ||
  { echo "$out"; echo "bad up/down figures"; exit 1; }
for spec in yinyang latlon fibonacci; do
  o=$("$panoptes" rig "$spec")
  [ "$(echo "$o" | grep -c "then .* returns for 100.0 % of cameras in the players")" = 4 ] ||
    { echo "$o"; echo "$spec: moves do not undo themselves"; exit 1; }
done

# Cameras inside the volume: distances in world units, not angles from the centre (issue 14).
out=$("$panoptes" rig lattice:4x4x3@0.05 --extent 25600,51200,16000)
echo "$out" | grep "^cameras  *48 inside the domain (lattice)$" >/dev/null || { echo "$out"; echo "bad lattice count"; exit 1; }
echo "$out" | grep "^lattice  *4 x 4 x 3 nodes, spacing 5760, 11520, 4800 (x, y, z)$" >/dev/null || { echo "$out"; echo "bad lattice spacing"; exit 1; }
echo "$out" | grep "^neighbour distance  *4800 .. 11520 " >/dev/null || { echo "$out"; echo "bad walk steps"; exit 1; }
echo "$out" | grep "^missing moves  *27.8 % of the six moves" >/dev/null || { echo "$out"; echo "bad missing moves"; exit 1; }
if echo "$out" | grep -q "deg (max/min\|covering radius"; then echo "$out"; echo "sphere statistics printed for a lattice"; exit 1; fi
stats=$("$panoptes" rig lattice:3x2x2 --json | sed -n '/"statistics"/,$p' | tr -d ' \n')  # no Python start-up (1 s under load)
case "$stats" in *'"lattice":[3,2,2]'*'"reverse_return":1.0'*'"spacing":[0.33333333333333337,0.5,0.5],"strongly_connected":true'*) ;;
  *) echo "$stats"; echo "bad lattice JSON statistics"; exit 1 ;; esac

: 3 x 130 cameras, in/out columns filled.
"$panoptes" rig shells:yinyang@1.5,2.5,4 --list --no-stats > "$tmp/list.txt"
grep -q "^cameras  *390 on 3 shells$" "$tmp/list.txt"
[ "$(grep -cE '^ +[0-9]+ (yin|yang) ' "$tmp/list.txt")" = 390 ] || { echo "list has wrong row count"; exit 1; }

# JSON: every neighbour id is valid and never the camera itself; shells and labels present.
"$panoptes" rig fibonacci:300@2,4 --json > "$tmp/rig.json"
python3 - "$tmp/rig.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
cams = j["cameras"]
assert len(cams) == 600 and j["shells"] == 2, (len(cams), j["shells"])
for c in cams:
    for k, v in c["neighbours"].items():
        assert -1 <= v < len(cams) and v != c["id"], (c["id"], k, v)
    assert c["patch"] == "fibonacci" and c["shell"] in (0, 1)
    assert (c["neighbours"]["in"] >= 0) == (c["shell"] == 0)
assert j["statistics"]["strongly_connected"] is True
print("rig json ok")
PY

# Camera files (text and JSON) and nearest-camera lookup.
printf '# x y z\n10 0 0\n0 10 0\n-10 0 0\n0 -10 0\n0 0 10\n0 0 -10\n' > "$tmp/cams.txt"
out=$("$panoptes" rig "$tmp/cams.txt" --nearest 5,85)
echo "$out" | grep "^cameras  *6 on 1 shell$" >/dev/null || { echo "$out"; exit 1; }
echo "$out" | grep "nearest to lat 5 lon 85 on shell 0: camera 1$" >/dev/null || { echo "$out"; exit 1; }
echo '{"cameras": [{"position": [0, 0, 9]}, {"position": [9, 0, 0], "fov_y_degrees": 30}]}' > "$tmp/cams.json"
"$panoptes" rig "file:$tmp/cams.json" --json | python3 -c 'import json,sys; j=json.load(sys.stdin); assert j["cameras"][1]["fov_y_degrees"]==30'

# Errors: one line, exit status 1, naming the bad value.
expect_error() {  # expect_error NEEDLE ARGS...
  local needle=$1; shift
  if "$panoptes" "$@" > /dev/null 2> "$tmp/err"; then echo "accepted: $*"; exit 1; fi
  grep -q "^panoptes: error: .*$needle" "$tmp/err" || { cat "$tmp/err"; echo "missing '$needle' for: $*"; exit 1; }
}
expect_error "yinyang:5xq" rig yinyang:5xq
expect_error "no-such-rig" rig no-such-rig
expect_error "extent" rig yinyang --extent 1,0,1
printf '1 2\n' > "$tmp/bad.txt"
expect_error "line 1" rig "$tmp/bad.txt"
echo "rig: ok"
