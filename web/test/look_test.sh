#!/usr/bin/env bash
# The web player inside a 360° lattice database (look_test.mjs): `panoptes synth-db --lattice 3x3x3
# --projection equirectangular` (tiny), served by `panoptes serve`, driven in headless Chromium.
#   look_test.sh PANOPTES NODE_MODULES CHROMIUM [SCREENSHOT_DIR]
set -euo pipefail
panoptes=$(realpath "$1") node_modules=$(realpath "$2") chromium=$3 shots=${4:-}
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

"$panoptes" synth-db "$tmp/db" --lattice 3x3x3 --projection equirectangular --tasks 2 --frames 24 --size 256x128 --gop 4 >/dev/null
# A sphere rig (perspective, navigation graph) for the same key script through both players.
"$panoptes" synth-db "$tmp/sphere" --cameras 12 --tasks 3 --frames 8 --size 96x64 --gop 4 >/dev/null
serve_db "$tmp/db" "$tmp/serve.log" --quiet
url=$served_url
serve_db "$tmp/sphere" "$tmp/sphere.log" --quiet
sphere_url=$served_url
export NODE_PATH=$node_modules
node "$here/look_test.mjs" "$url" "$chromium" "$node_modules" "$panoptes" "$tmp/db" "$shots" "${LOOK_TEST_SWITCHES:-40}" "$sphere_url" "$tmp/sphere"
