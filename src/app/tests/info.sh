#!/usr/bin/env bash
# `panoptes info`: summary and JSON of a database, exit 2 with the list of broken movies, a one-line
# error (exit 1) for anything that is not a database, and `interrupted` for a killed writer.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "info.sh: $*"; exit 1; }

"$panoptes" synth-db "$tmp/db" --cameras 4 --tasks 3 --frames 5 --size 64x64 --gop 5 >/dev/null
out=$("$panoptes" info "$tmp/db")
for want in "status     complete" "cameras    4 (rig fibonacci; navigation graph present)" \
            "tasks      3 (synthetic)" "axes       isovalue (3 values" "frames     5" "image      64x64" \
            "gop 5" "streams    12" "checked    12 of 12 movies: all readable"; do
  grep -qF "$want" <<<"$out" || fail "missing '$want' in:
$out"
done

json=$("$panoptes" info "$tmp/db" --json --decode)
for want in '"status": "complete"' '"cameras": 4' '"tasks": 3' '"streams": 12' '"frames": 5' \
            '"checked": 12' '"problems": []' '"decoded_all_frames": true' '"bytes_on_disk": '; do
  grep -qF "$want" <<<"$json" || fail "missing '$want' in JSON:
$json"
done

# Broken movies: listed, exit status 2, no error line.
rm "$tmp/db/movies/c1/t2.mp4"
echo "not a movie" >"$tmp/db/movies/c3/t0.mp4"
set +e
out=$("$panoptes" info "$tmp/db" 2>"$tmp/err"); rc=$?
set -e
[ "$rc" -eq 2 ] || fail "exit status $rc with broken movies (expected 2)"
grep -q "checked    12 of 12 movies: 2 with problems" <<<"$out" || fail "no problem count in: $out"
grep -q "missing .*movies/c1/t2.mp4: movie missing" <<<"$out" || fail "missing movie not listed: $out"
grep -q "unreadable .*movies/c3/t0.mp4: not a readable movie" <<<"$out" || fail "bad movie not listed: $out"
"$panoptes" info "$tmp/db" --no-check | grep "checked    no movie" >/dev/null || fail "--no-check"

# Not a database: one line on stderr, exit 1.
mkdir "$tmp/empty"
for target in "$tmp/empty" "$tmp/nowhere" "$tmp/db/movies/c0/t0.mp4"; do
  set +e
  "$panoptes" info "$target" >/dev/null 2>"$tmp/err"; rc=$?
  set -e
  [ "$rc" -eq 1 ] || fail "exit status $rc for $target (expected 1)"
  [ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "not one line: $(cat "$tmp/err")"
  grep -q "^panoptes: error: $target" "$tmp/err" || fail "message does not name $target: $(cat "$tmp/err")"
done
grep -q "no manifest here (not a Panoptes database)" <(("$panoptes" info "$tmp/empty" 2>&1) || true) || fail "empty dir message"
echo '{"schema_version": 9}' >"$tmp/empty/panoptes.json"
grep -q "schema_version 9 is not supported" <(("$panoptes" info "$tmp/empty" 2>&1) || true) || fail "schema message"

# A writer killed mid-run leaves a database that reports `interrupted`.
"$panoptes" synth-db "$tmp/killed" --cameras 3000 --tasks 1 --frames 10 --size 64x64 --threads 1 >/dev/null 2>&1 &
writer=$!
for _ in $(seq 50); do [ -f "$tmp/killed/panoptes.json" ] && break; sleep 0.1; done
sleep 0.3
if kill -9 "$writer" 2>/dev/null; then
  wait "$writer" 2>/dev/null || true
  "$panoptes" info "$tmp/killed" --no-check | grep "status     interrupted (stored as running; no live writer holds the lock)" >/dev/null \
    || fail "killed writer not reported as interrupted: $("$panoptes" info "$tmp/killed" --no-check)"
else
  echo "info.sh: writer finished before it could be killed; interrupted check skipped"
fi
echo "info: ok"
