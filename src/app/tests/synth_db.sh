#!/usr/bin/env bash
# `panoptes synth-db`: writes a stamped database, refuses to overwrite one unless told, rejects bad
# arguments with one-line errors, and writes 2,000 tiny streams quickly.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "synth_db.sh: $*"; exit 1; }

out=$("$panoptes" synth-db "$tmp/db" --cameras 3 --tasks 2 --frames 4 --size 64x48 --gop 2 --crf 28)
grep -q "3 cameras x 2 tasks = 6 streams, 4 frames of 64x48" <<<"$out" || fail "unexpected output: $out"
[ -f "$tmp/db/panoptes.json" ] || fail "no manifest"
[ "$(find "$tmp/db/movies" -name '*.mp4' | wc -l)" -eq 6 ] || fail "expected 6 movies"
grep -Eq '"gop": ?2' "$tmp/db/panoptes.json" || fail "gop not recorded"
grep -Eq '"crf": ?28' "$tmp/db/panoptes.json" || fail "crf not recorded"
grep -Eq '"status": ?"complete"' "$tmp/db/panoptes.json" || fail "status not complete"

# An existing database is refused (one line, exit 1) and left intact; --overwrite replaces it.
if "$panoptes" synth-db "$tmp/db" --cameras 1 --tasks 1 2>"$tmp/err"; then fail "overwrote without --overwrite"; fi
[ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "error is not one line: $(cat "$tmp/err")"
grep -q "^panoptes: error: .*already holds a Panoptes database" "$tmp/err" || fail "bad message: $(cat "$tmp/err")"
# Issue 44: the advice is the command's option, not a C++ setting.
grep -q "(--overwrite replaces it)" "$tmp/err" || fail "the refusal does not name --overwrite: $(cat "$tmp/err")"
grep -q "WriterOptions" "$tmp/err" && fail "the refusal names a C++ setting: $(cat "$tmp/err")"
[ "$(find "$tmp/db/movies" -name '*.mp4' | wc -l)" -eq 6 ] || fail "refused run touched the movies"
"$panoptes" synth-db "$tmp/db" --cameras 1 --tasks 1 --frames 2 --overwrite >/dev/null
[ "$(find "$tmp/db/movies" -name '*.mp4' | wc -l)" -eq 1 ] || fail "--overwrite left old movies"

# Bad arguments: one-line errors, exit status 1 (CLI11 parse errors use their own codes, non-zero).
check_error() {  # expected-text args...
  local expected=$1; shift
  if "$panoptes" synth-db "$@" >/dev/null 2>"$tmp/err"; then fail "accepted: $*"; fi
  grep -q -- "$expected" "$tmp/err" || fail "for '$*' expected '$expected', got: $(cat "$tmp/err")"
}
check_error 'expected WIDTHxHEIGHT' "$tmp/bad1" --size big
check_error 'too small' "$tmp/bad2" --size 16x16
check_error 'crf' "$tmp/bad3" --crf 99
check_error 'cameras' "$tmp/bad4" --cameras 0
[ ! -e "$tmp/bad1/panoptes.json" ] || fail "a refused run left a manifest"

# Many tiny streams, in parallel: 500 here (the 10,000-stream figure is in bench/store_bench).
start=$(date +%s%N)
"$panoptes" synth-db "$tmp/many" --cameras 250 --tasks 2 --frames 10 --size 64x64 >/dev/null
elapsed_ms=$((($(date +%s%N) - start) / 1000000))
[ "$(find "$tmp/many/movies" -name '*.mp4' | wc -l)" -eq 500 ] || fail "expected 500 movies"
echo "synth-db: 500 streams of 10 frames 64x64 in ${elapsed_ms} ms"
# Issue 15: counts and memory are checked before anything is written; --force overrides the estimate.
if "$panoptes" synth-db "$tmp/huge" --cameras 16000000 --tasks 65536 2> "$tmp/err.txt"; then fail "accepted 10^12 streams"; fi
grep -q "16000000 x 65536 is more than the limit" "$tmp/err.txt" || fail "overflow: $(cat "$tmp/err.txt")"
if PANOPTES_MEMORY_LIMIT=1M "$panoptes" synth-db "$tmp/small" --cameras 2 --tasks 1 --frames 1 2> "$tmp/err.txt"; then
  fail "accepted with 1 MB"
fi
grep -q "1.0 MB available (PANOPTES_MEMORY_LIMIT)" "$tmp/err.txt" || fail "memory: $(cat "$tmp/err.txt")"
[ ! -e "$tmp/small" ] || fail "refused run created its database"
PANOPTES_MEMORY_LIMIT=1M "$panoptes" synth-db "$tmp/small" --cameras 2 --tasks 1 --frames 1 --force > /dev/null || fail "--force"
echo "synth_db: ok"
