#!/usr/bin/env bash
# The web player on a packed database (issue 46): `panoptes serve` of it, and its `export-web` site
# behind a static server that honours byte ranges (as real static hosts and object stores do), with
# no Panoptes server and no file per stream. One frame of one stream is damaged in its pack first.
#   packed_test.sh PANOPTES NODE_MODULES CHROMIUM
set -euo pipefail
panoptes=$(realpath "$1") node_modules=$(realpath "$2") chromium=$3
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
. "$here/serve_db.sh"
cleanup() {
  local rc=$?
  serve_db_stop || rc=1
  wait 2>/dev/null || true
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT

"$panoptes" synth-db "$tmp/db" --layout packed --cameras 6 --tasks 2 --frames 12 --size 160x120 >/dev/null
# Frame 2 of stream (camera 1, task 0) damaged: a byte of its picture data flipped, found through the
# pack index (docs/formats.md, Packed layout: one rank, so camera c is slot c).
python3 - "$tmp/db/packs/s0-r0.idx" "$tmp/db/packs/s0-r0.pack" <<'PY'
import struct, sys
idx = open(sys.argv[1], "rb").read()
header, nc, nt = struct.unpack_from("<I", idx, 12)[0], *struct.unpack_from("<II", idx, 24)
camera, task, frame = 1, 0, 2
offset, size, first, frames = struct.unpack_from("<QIII", idx, header + frame * 24 * nc * nt + (camera * nt + task) * 24)
assert (first, frames) == (frame, 1), (first, frames)
with open(sys.argv[2], "r+b") as pack:
    pack.seek(offset + size - 8)
    b = pack.read(1)
    pack.seek(offset + size - 8)
    pack.write(bytes([b[0] ^ 0x5A]))
PY
"$panoptes" export-web "$tmp/db" "$tmp/site" >/dev/null
# No file per stream in the site: the player, api/{database,keys}.json, one stream index shard, the
# manifest, camera table, one pack and its index.
streams=$(find "$tmp/site/api" "$tmp/site/db" -type f | wc -l)
[ "$streams" -eq 7 ] || { echo "expected 7 files under api/ and db/, found $streams:"; find "$tmp/site/api" "$tmp/site/db" -type f; exit 1; }

serve_db "$tmp/db" "$tmp/serve.log"
export NODE_PATH=$node_modules
if ! node "$here/packed_test.mjs" "$served_url" "$tmp/site" "$chromium" "$node_modules"; then
  echo "--- serve log (last 30 lines)"; tail -30 "$tmp/serve.log"
  exit 1
fi
