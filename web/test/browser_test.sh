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
. "$here/serve_db.sh"  # serve_db DB LOG [ARGS], serve_db_stop: every server stopped and checked at exit
cleanup() {
  local rc=$?
  serve_db_stop || rc=1
  wait 2>/dev/null || true
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT

"$panoptes" synth-db "$tmp/db" --cameras 8 --tasks 3 --frames 24 --size 160x120 --gop 4 >/dev/null
rm "$tmp/db/movies/c5/t1.mp4"                                   # missing
head -c 3000 /dev/urandom > "$tmp/db/movies/c4/t0.mp4"          # corrupt

serve_db "$tmp/db" "$tmp/serve.log" --token t0k3n
url=$served_url

"$panoptes" export-web "$tmp/db" "$tmp/site" >/dev/null

# A "running" database: this script holds its writer lock (fd 9) until it exits.
# gop 1 (keyframes only), so that a playing neighbour is decoded at every second frame (nbstride).
"$panoptes" synth-db "$tmp/live" --cameras 2 --tasks 1 --frames 16 --size 160x120 --gop 1 >/dev/null
exec 9>"$tmp/live/.panoptes.lock"
flock -x 9
serve_db "$tmp/live" "$tmp/live.log"
live_url=$served_url

export NODE_PATH=$node_modules
if ! node "$here/browser_test.mjs" "$url" "$tmp/site" "$chromium" "$node_modules" "$live_url" "$tmp/live"; then
  echo "--- serve log (last 30 lines)"; tail -30 "$tmp/serve.log"
  exit 1
fi
# The server logged the refused request of the test's token-less context.
grep -q " 401 refused: missing or wrong token" "$tmp/serve.log" || { echo "no 401 log line"; exit 1; }
