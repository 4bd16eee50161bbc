#!/usr/bin/env bash
# Issue 30, 43: ONE key script gives the same state after every line in every front end — `play
# --headless`, the window (Xvfb, software GL), Python's Player and the web player (headless Chromium):
# camera, task, frame, the active parameter axis and the camera's shell, and (window, browser) the words
# a refused key shows. Two databases: a sphere rig of 3 camera shells with 3 parameter axes (Z / X,
# A / Shift+A, PageUp / PageDown all change something) and a 360° equirectangular 3x3x3 lattice (where the
# arrows and PageUp/PageDown walk relative to the view, and Shift+A does nothing). Legs whose front end
# is not built (the UI, the Python module) or not installed (xvfb-run) are skipped with a line saying
# so; headless and web always run.
#   same_keys.sh PANOPTES NODE_MODULES CHROMIUM
set -euo pipefail
panoptes=$(realpath "$1") node_modules=$(realpath "$2") chromium=$3
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "$(dirname "$panoptes")/.." && pwd)
tmp=$(mktemp -d)
pids=()
windows=()
. "$here/serve_db.sh"  # serve_db DB LOG [ARGS], serve_db_stop
cleanup() {
  local rc=$?
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  serve_db_stop || rc=1
  wait 2>/dev/null || true
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT
fail() { echo "same_keys.sh: $*"; exit 1; }
cd "$tmp"

"$panoptes" synth-db sphere --cameras 6 --shells 3 --axes 3x2x2 --frames 8 --size 96x64 --gop 4 >/dev/null
"$panoptes" synth-db lattice --lattice 3x3x3 --projection equirectangular --tasks 3 --frames 8 --size 128x64 --gop 4 >/dev/null
keys=(Up Right PageUp Z Tab Period Shift+A PageUp Z Z X Shift+A Shift+A PageDown Left A PageUp Down Shift+Tab End
      Comma 3 Right Up X Right Home Left PageDown)
for i in "${!keys[@]}"; do printf 't=%s key=%s\n' "$(awk "BEGIN{print $i / 10}")" "${keys[$i]}"; done > s.txt
printf 't=%s end\n' "$(awk "BEGIN{print ${#keys[@]} / 10 + 0.3}")" >> s.txt
start() { [ "$1" = lattice ] && echo 13 || echo 5; }  # the lattice's centre camera; any sphere camera
# One row per script line: camera task frame axis shell (the state every front end has).
rows() { /usr/bin/python3 -c 'import json, sys; [print(r["camera"], r["task"], r["frame"], r["axis"], r["shell"]) for r in map(json.loads, open(sys.argv[1]))]' "$1"; }
# The refusal texts of the lines (window and browser show them; "-" = none).
refusals() { /usr/bin/python3 -c 'import json, sys; [print(r.get("refusal") or "-") for r in map(json.loads, open(sys.argv[1]))]' "$1"; }

python_leg() {  # DB START OUT
  PYTHONPATH="$build/python" /usr/bin/python3 - "$@" "${keys[@]}" <<'PY'
import sys, panoptes
db, start, out, keys = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4:]
p = panoptes.Player(db, camera=start)
shells = panoptes.Database(db).cameras.shell
with open(out, "w") as f:
    for k in keys:
        p.key(k)
        print(p.camera, p.task, p.frame_index, p.active_axis, int(shells[p.camera]), file=f)
PY
}

have_window=0
if command -v xvfb-run >/dev/null && [[ $("$panoptes" play --help) == *--software* ]]; then have_window=1; fi
have_python=0
if ls "$build"/python/panoptes/_panoptes*.so >/dev/null 2>&1; then have_python=1; fi
[ $have_window = 1 ] || echo "same_keys.sh: no xvfb-run or no UI build: the window leg is skipped"
[ $have_python = 1 ] || echo "same_keys.sh: the Python module is not built: the Python leg is skipped"

export NODE_PATH=$node_modules
# The window legs run in the background while the others do: their script runs on the wall clock.
for db in sphere lattice; do
  if [ $have_window = 1 ]; then
    (timeout 120 xvfb-run -a "$panoptes" play $db --paused --camera "$(start $db)" --software --width 320 --height 160 \
      --script s.txt --trace w_$db.jsonl --max-frames 100000 >/dev/null 2>&1 || true) &
    pids+=($!)
    windows+=($!)
  fi
done
web_args=()
for db in sphere lattice; do
  "$panoptes" play $db --headless --paused --camera "$(start $db)" --script s.txt --trace h_$db.jsonl >/dev/null
  rows h_$db.jsonl > $db.headless
  refusals h_$db.jsonl > $db.headless.refusals
  [ "$(wc -l < $db.headless)" = ${#keys[@]} ] || { cat h_$db.jsonl; fail "$db: expected ${#keys[@]} headless trace lines"; }
  [ $have_python = 1 ] && python_leg $db "$(start $db)" $db.python
  serve_db $db $db.serve.log --quiet
  web_args+=("$served_url" "$(start $db)" $db.web)
done
node "$here/same_keys.mjs" "$chromium" "$node_modules" s.txt "${web_args[@]}" || fail "the web leg failed"
for w in "${windows[@]}"; do wait "$w" || true; done
for db in sphere lattice; do
  legs=(web)
  [ $have_python = 1 ] && legs+=(python)
  if [ $have_window = 1 ]; then
    [ -f w_$db.jsonl ] || fail "$db: the window wrote no trace"
    rows w_$db.jsonl > $db.window
    refusals w_$db.jsonl > $db.window.refusals
    legs+=(window)
  fi
  for leg in "${legs[@]}"; do
    if ! diff <(paste -d' ' <(printf '%s\n' "${keys[@]}") $db.headless) <(paste -d' ' <(printf '%s\n' "${keys[@]}") $db.$leg) > d.txt; then
      cat d.txt
      fail "$db: $leg differs from play --headless (< headless, > $leg; key camera task frame axis shell)"
    fi
    [ -f $db.$leg.refusals ] || continue
    if ! diff <(paste -d' ' <(printf '%s\n' "${keys[@]}") $db.headless.refusals) <(paste -d' ' <(printf '%s\n' "${keys[@]}") $db.$leg.refusals) > d.txt; then
      cat d.txt
      fail "$db: $leg says other words than play --headless for refused keys (< headless, > $leg)"
    fi
  done
  # The headless reference must not be trivial: the script visits several cameras, tasks and frames,
  # every axis on the axes database and every shell on the shells one, and some keys are refused.
  column() { cut -d' ' -f"$1" $db.headless | sort -u | wc -l; }
  [ "$(column 1)" -ge 3 ] || fail "$db: the script visits fewer than 3 cameras"
  [ "$(column 2)" -ge 2 ] || fail "$db: the script visits fewer than 2 tasks"
  [ "$(column 3)" -ge 3 ] || fail "$db: the script visits fewer than 3 frames"
  if [ $db = sphere ]; then
    [ "$(column 4)" -ge 3 ] || fail "$db: the script makes fewer than 3 parameter axes active"
    [ "$(column 5)" -ge 3 ] || fail "$db: the script visits fewer than 3 camera shells"
    # Shift+A is not A: the line after the first Shift+A has the last axis active, not the second.
    i=$(printf '%s\n' "${keys[@]}" | grep -nx 'Shift+A' | head -1 | cut -d: -f1)
    [ "$(sed -n "${i}p" $db.headless | cut -d' ' -f4)" = 2 ] || fail "$db: Shift+A from axis 0 did not make axis 2 active"
  fi
  [ "$(grep -cv '^-$' $db.headless.refusals)" -ge 2 ] || fail "$db: fewer than 2 refused keys in the script"
  echo "same_keys.sh: $db: ${#keys[@]} keys, headless = ${legs[*]}; cameras $(cut -d' ' -f1 $db.headless | tr '\n' ' ')"
done
echo "same_keys.sh: ok"
