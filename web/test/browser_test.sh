#!/usr/bin/env bash
# Browser tests of the web player: headless Chromium (Debian's) driven by puppeteer-core against
# `panoptes serve` on a stamped synthetic database with one missing and one corrupt movie, then the
# same player exported by `panoptes export-web` behind a plain static file server that ignores byte
# ranges (started by browser_test.mjs).
#   browser_test.sh PANOPTES NODE_MODULES CHROMIUM
set -euo pipefail
panoptes=$(realpath "$1") node_modules=$(realpath "$2") chromium=$3
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT

"$panoptes" synth-db "$tmp/db" --cameras 8 --tasks 3 --frames 24 --size 160x120 --gop 4 >/dev/null
rm "$tmp/db/movies/c5/t1.mp4"                                   # missing
head -c 3000 /dev/urandom > "$tmp/db/movies/c4/t0.mp4"          # corrupt

# start_serve LOG ARGS...: starts `panoptes serve ARGS` in the background (logging to LOG) and sets
# served_url to the URL it prints once it listens.
start_serve() {
  local log=$1
  shift
  # The log exists before the server starts: the background job's redirection may run after the first
  # sed below, which (under set -e) would end the test on a missing file.
  : > "$log"
  "$panoptes" serve "$@" > "$log" 2>&1 &
  pids+=($!)
  served_url=""
  for _ in $(seq 100); do
    served_url=$(sed -n 's/^serving .* at \(http[^ ]*\)$/\1/p' "$log")
    [ -n "$served_url" ] && return 0
    sleep 0.1
  done
  echo "serve $* did not start:"
  cat "$log"
  exit 1
}

start_serve "$tmp/serve.log" "$tmp/db" --port 0 --token t0k3n
url=$served_url

"$panoptes" export-web "$tmp/db" "$tmp/site" >/dev/null

# A "running" database: this script holds its writer lock (fd 9) until it exits.
# gop 1 (keyframes only), so that a playing neighbour is decoded at every second frame (nbstride).
"$panoptes" synth-db "$tmp/live" --cameras 2 --tasks 1 --frames 16 --size 160x120 --gop 1 >/dev/null
exec 9>"$tmp/live/.panoptes.lock"
flock -x 9
start_serve "$tmp/live.log" "$tmp/live" --port 0
live_url=$served_url

export NODE_PATH=$node_modules
if ! node "$here/browser_test.mjs" "$url" "$tmp/site" "$chromium" "$node_modules" "$live_url" "$tmp/live"; then
  echo "--- serve log (last 30 lines)"; tail -30 "$tmp/serve.log"
  exit 1
fi
# The server logged the refused request of the test's token-less context.
grep -q " 401 refused: missing or wrong token" "$tmp/serve.log" || { echo "no 401 log line"; exit 1; }
