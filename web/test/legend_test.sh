#!/usr/bin/env bash
# Slice legends and the value readout in the web player (legend_test.mjs, issue 41): an analytic field
# (the one of src/player/value_readout_test.cpp) is rendered by `panoptes render` as a z slice seen from
# straight above, served by `panoptes serve` and checked in headless Chromium: the legend canvas's
# colours against the frame's pixels at known values, and the readout against the field.
#   legend_test.sh PANOPTES NODE_MODULES CHROMIUM [SCREENSHOT_DIR]
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

/usr/bin/python3 - "$tmp" <<'PY'
import sys, numpy as np
out = sys.argv[1]
nx, ny, nz = 64, 48, 32
z, y, x = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
for s, amplitude in enumerate([3e-5, 6e-5]):
    f = amplitude * np.sin(2 * np.pi * x / (nx - 1)) * np.cos(np.pi * y / (ny - 1))
    np.save(f"{out}/f_{s}.npy", f.astype("<f4"))
with open(f"{out}/camera.txt", "w") as c:
    c.write(f"{(nx - 1) / 2} {(ny - 1) / 2} {(nz - 1) / 2 + 80} {(nx - 1) / 2} {(ny - 1) / 2} {(nz - 1) / 2} 0 1 0 40\n")
PY
"$panoptes" render "$tmp/f_0.npy" "$tmp/f_1.npy" --rig "$tmp/camera.txt" --task slice:z:0.5 --size 256x192 \
  --no-outline -q --out "$tmp/db"
serve_db "$tmp/db" "$tmp/serve.log" --quiet
url=$served_url
export NODE_PATH=$node_modules
node "$here/legend_test.mjs" "$url" "$chromium" "$node_modules" "$shots"
