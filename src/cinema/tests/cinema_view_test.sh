#!/usr/bin/env bash
# Cinema:View (the viewer Debian ships in python3-paraview's cinemasci) opens a database written by
# `panoptes export-cinema`: headless Chromium driven by puppeteer-core (cinema_view_test.mjs) checks
# that the first screen is an image and that moving each slider changes it, and that every image is
# reachable from the sliders; Cinema:Explorer, beside it, selects all rows and shows the images. Run on
# a synthetic database and on ParaView's own extracts after import-cinema.
#   cinema_view_test.sh PANOPTES NODE_MODULES CHROMIUM VIEWERS_DIR [SCREENSHOT]
set -euo pipefail
panoptes=$(realpath "$1") node_modules=$(realpath "$2") chromium=$3 viewers=$4 shot=${5:-}
here=$(cd "$(dirname "$0")" && pwd)
[ -f "$viewers/cinema_view.html" ] || { echo "no Cinema:View in $viewers (scripts/setup installs python3-paraview)"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$panoptes" synth-db "$tmp/db" --cameras 4 --tasks 3 --frames 3 --size 96x64 >/dev/null
mkdir "$tmp/site"
"$panoptes" export-cinema "$tmp/db" "$tmp/site/panoptes.cdb" >/dev/null
# The viewer's own files, as Debian installs them (the page loads d3 from d3js.org: the test answers
# that request with the copy beside it, cinema/lib/d3.v4.min.js; nothing is fetched).
ln -s "$viewers/cinema_view.html" "$tmp/site/cinema_view.html"
ln -s "$viewers/cinema_explorer.html" "$tmp/site/cinema_explorer.html"
ln -s "$viewers/cinema" "$tmp/site/cinema"
NODE_PATH=$node_modules node "$here/cinema_view_test.mjs" "$tmp/site" "$chromium" "$node_modules" panoptes.cdb 36 "$shot"
# Both ways: the database ParaView 5.11's extractors wrote (12 phi/theta cameras, two extractors as a
# text column, 3 times) imported, exported again, and opened in the same viewers: sliders time, phi,
# theta and task, all 72 images reachable.
"$panoptes" import-cinema "$here/../fixtures/paraview_extracts.cdb" "$tmp/pv" >/dev/null
"$panoptes" export-cinema "$tmp/pv" "$tmp/site/paraview.cdb" >/dev/null
NODE_PATH=$node_modules node "$here/cinema_view_test.mjs" "$tmp/site" "$chromium" "$node_modules" paraview.cdb 72 \
  "${shot:+${shot%.png}-paraview.png}"
