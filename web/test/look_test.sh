#!/usr/bin/env bash
# The web player inside a 360° lattice database (look_test.mjs): `panoptes synth-db --lattice 3x3x3
# --projection equirectangular` (tiny), served by `panoptes serve`, driven in headless Chromium.
#   look_test.sh PANOPTES NODE_MODULES CHROMIUM [SCREENSHOT_DIR]
set -euo pipefail
panoptes=$(realpath "$1") node_modules=$(realpath "$2") chromium=$3 shots=${4:-}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
pid=""
cleanup() {
  [ -n "$pid" ] && kill "$pid" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT

"$panoptes" synth-db "$tmp/db" --lattice 3x3x3 --projection equirectangular --tasks 2 --frames 24 --size 256x128 --gop 4 >/dev/null
: > "$tmp/serve.log"
"$panoptes" serve "$tmp/db" --port 0 --quiet > "$tmp/serve.log" 2>&1 &
pid=$!
url=""
for _ in $(seq 100); do
  url=$(sed -n 's/^serving .* at \(http[^ ]*\)$/\1/p' "$tmp/serve.log")
  [ -n "$url" ] && break
  sleep 0.1
done
[ -n "$url" ] || { echo "serve did not start:"; cat "$tmp/serve.log"; exit 1; }
export NODE_PATH=$node_modules
node "$here/look_test.mjs" "$url" "$chromium" "$node_modules" "$panoptes" "$tmp/db" "$shots" "${LOOK_TEST_SWITCHES:-40}"
