#!/usr/bin/env bash
# `panoptes export-cinema` / `import-cinema`: a database out to Cinema Spec D and back, checked with
# `panoptes info`; bad inputs give one-line errors naming the file and line.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "cinema.sh: $*"; exit 1; }

"$panoptes" synth-db "$tmp/db" --cameras 3 --tasks 2 --frames 4 --size 64x48 >/dev/null
out=$("$panoptes" export-cinema "$tmp/db" "$tmp/x.cdb" --frames 0:4:2 --format jpg)
grep "Cinema Spec D, 12 jpg images" <<<"$out" >/dev/null || fail "unexpected export output: $out"
head -1 "$tmp/x.cdb/data.csv" | grep '^time,camera,task_name,isovalue,FILE' >/dev/null || fail "bad header: $(head -1 "$tmp/x.cdb/data.csv")"
[ "$(find "$tmp/x.cdb/image" -name '*.jpg' | wc -l)" -eq 12 ] || fail "expected 12 images"

out=$("$panoptes" import-cinema "$tmp/x.cdb" "$tmp/back")
grep "from Cinema Spec D: 3 cameras x 2 tasks = 6 movies, 2 frames each" <<<"$out" >/dev/null || fail "unexpected import output: $out"
grep "cameras: Panoptes export-cinema" <<<"$out" >/dev/null || fail "sidecar not used: $out"
info=$("$panoptes" info --json "$tmp/back")
grep -Eq '"status": *"complete"' <<<"$info" >/dev/null || fail "imported database not complete: $info"

# An existing database is refused; a bad Cinema database is one error line naming file and line.
if "$panoptes" import-cinema "$tmp/x.cdb" "$tmp/back" 2>"$tmp/err"; then fail "overwrote without --overwrite"; fi
grep -q "^panoptes: error: .*already holds a Panoptes database" "$tmp/err" || fail "bad message: $(cat "$tmp/err")"
grep -q "(--overwrite replaces it)" "$tmp/err" || fail "the refusal does not name --overwrite: $(cat "$tmp/err")"  # issue 44
printf 'time,phi,theta,FILE\n0,0,north,image/c0/t0/f0.jpg\n' >"$tmp/x.cdb/data.csv"
if "$panoptes" import-cinema "$tmp/x.cdb" "$tmp/bad" 2>"$tmp/err"; then fail "accepted a non-numeric theta"; fi
[ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "error is not one line: $(cat "$tmp/err")"
grep -q '^panoptes: error: .*x.cdb/data.csv line 2: theta "north" (column theta) is not a number$' "$tmp/err" ||
  fail "bad message: $(cat "$tmp/err")"
# Angles whose producer cannot be told are refused with the option to pass; with it they import.
rm "$tmp/x.cdb/panoptes-cinema.json"
printf 'time,phi,theta,FILE\n0,0,0,image/c0/t0_f0.jpg\n0,90,30,image/c1/t0_f0.jpg\n' >"$tmp/x.cdb/data.csv"
if "$panoptes" import-cinema "$tmp/x.cdb" "$tmp/amb" 2>"$tmp/err"; then fail "guessed a phi/theta convention"; fi
grep -q '^panoptes: error: .*cannot tell which producer.*--angles paraview|cinema-python|ascent|elevation' "$tmp/err" ||
  fail "bad message: $(cat "$tmp/err")"
out=$("$panoptes" import-cinema "$tmp/x.cdb" "$tmp/amb" --angles elevation --azimuth-zero -x)
grep "cameras: generic Cinema (theta = elevation) (--angles elevation)" <<<"$out" >/dev/null || fail "unexpected import output: $out"
# issue 44 point 5: a cinema_python layout under ParaView's image column name is refused naming both
# pieces of evidence and --angles (it imported mirrored); a second image column is named in a warning.
mkdir -p "$tmp/cp.cdb/image/0" "$tmp/cp.cdb/image/90"
cp "$tmp/x.cdb/image/c0/t0_f0.jpg" "$tmp/cp.cdb/image/0/30.jpg"
cp "$tmp/x.cdb/image/c1/t0_f0.jpg" "$tmp/cp.cdb/image/90/30.jpg"
printf 'phi,theta,FILE_jpg\n0,30,image/0/30.jpg\n90,30,image/90/30.jpg\n' >"$tmp/cp.cdb/data.csv"
if "$panoptes" import-cinema "$tmp/cp.cdb" "$tmp/cp" 2>"$tmp/err"; then fail "imported disagreeing evidence"; fi
[ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "error is not one line: $(cat "$tmp/err")"
grep -q '^panoptes: error: .*cp.cdb/data.csv: the evidence disagrees .*FILE_jpg.*{phi}/{theta}.*--angles paraview|cinema-python$' "$tmp/err" ||
  fail "bad message: $(cat "$tmp/err")"
"$panoptes" import-cinema "$tmp/cp.cdb" "$tmp/cp" --angles cinema-python >/dev/null || fail "--angles cinema-python refused"
printf 'phi,theta,FILE,FILE2\n0,30,image/0/30.jpg,image/90/30.jpg\n90,30,image/90/30.jpg,image/0/30.jpg\n' >"$tmp/cp.cdb/data.csv"
"$panoptes" import-cinema "$tmp/cp.cdb" "$tmp/two" --angles elevation 2>"$tmp/err" >/dev/null || fail "FILE2 refused: $(cat "$tmp/err")"
grep -q '^panoptes: warning: .*data.csv line 2: rows have 2 images (columns FILE, FILE2); imported FILE.*--image-column FILE2' "$tmp/err" ||
  fail "no FILE2 warning: $(cat "$tmp/err")"
"$panoptes" import-cinema "$tmp/cp.cdb" "$tmp/two2" --angles elevation --image-column FILE2 >/dev/null 2>&1 || fail "--image-column FILE2"
# The databases the real producers wrote (src/cinema/fixtures) import as they are, each recognised.
fixtures=$(cd "$(dirname "$0")/../../cinema/fixtures" && pwd)
for want in "paraview_extracts:12 cameras x 2 tasks = 24 movies, 3 frames each:ParaView image extractor (camera mode Phi-Theta)" \
            "paraview_cinema_python:12 cameras x 3 tasks = 36 movies, 3 frames each:ParaView cinema_python (phi-theta camera)" \
            "ascent_convention:12 cameras x 1 tasks = 12 movies, 2 frames each:Ascent cinema extract"; do
  IFS=: read -r name counts producer <<<"$want"
  out=$("$panoptes" import-cinema "$fixtures/$name.cdb" "$tmp/$name") || fail "$name: import failed"
  grep -F "$counts" <<<"$out" >/dev/null || fail "$name: unexpected import output: $out"
  grep -F "cameras: $producer" <<<"$out" >/dev/null || fail "$name: producer not recognised: $out"
done
"$panoptes" export-cinema --help | grep -- "--format" >/dev/null || fail "export-cinema --help"
"$panoptes" import-cinema --help | grep -- "--group-by" >/dev/null || fail "import-cinema --help"
echo "cinema.sh: ok"
