#!/usr/bin/env bash
# Writers touch only what they own (issue #31, rows 1, 2 and 12): export-web never writes through a
# link it finds in OUT, --overwrite removes only what an earlier export listed, a failed export
# leaves nothing behind; a write past `ulimit -f` says so in one line.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "export_web: $*"; exit 1; }
tree_sum() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 md5sum); }

"$panoptes" synth-db "$tmp/A" --cameras 2 --tasks 1 --frames 2 --size 48x32 >/dev/null
"$panoptes" synth-db "$tmp/B" --cameras 3 --tasks 1 --frames 2 --size 48x32 >/dev/null
sum_a=$(tree_sum "$tmp/A")

# Row 1: A linked, then B copied over it: B's files land in the site, never in database A.
"$panoptes" export-web "$tmp/A" "$tmp/site" --link >/dev/null
[ -L "$tmp/site/db" ] || fail "--link made no link"
"$panoptes" export-web "$tmp/B" "$tmp/site" --overwrite >/dev/null
[ "$(tree_sum "$tmp/A")" = "$sum_a" ] || fail "database A was written through the site's db link"
[ ! -L "$tmp/site/db" ] && [ -f "$tmp/site/db/movies/c2/t0.mp4" ] || fail "B was not copied into the site"
cmp -s "$tmp/site/db/panoptes.json" "$tmp/B/panoptes.json" || fail "the site's manifest is not B's"

# Row 2: --overwrite removes what the last export listed and nothing else.
echo mine > "$tmp/site/notes.txt"
echo mine > "$tmp/site/api/index/mine.txt"
"$panoptes" export-web "$tmp/A" "$tmp/site" --overwrite --link >/dev/null
[ -f "$tmp/site/notes.txt" ] && [ -f "$tmp/site/api/index/mine.txt" ] || fail "a file the export never wrote was removed"
[ ! -e "$tmp/site/api/index/2" ] || fail "B's stale index (camera 2) was left"
[ -L "$tmp/site/db" ] && [ "$(tree_sum "$tmp/A")" = "$sum_a" ] || fail "relinking A changed it"

# A file of the user's where the new site needs a place: refused before anything changes.
sum_site=$(tree_sum "$tmp/site")
rm "$tmp/site/db" && echo mine > "$tmp/site/db" && sed -i '/^db$/d' "$tmp/site/.panoptes-site"
sum_site=$(tree_sum "$tmp/site")
if "$panoptes" export-web "$tmp/B" "$tmp/site" --overwrite 2>"$tmp/err" >/dev/null; then fail "replaced the user's db file"; fi
grep -q "^panoptes: error: .*site/db: exists and was not written by export-web" "$tmp/err" || { cat "$tmp/err"; fail "unclear refusal"; }
[ "$(tree_sum "$tmp/site")" = "$sum_site" ] || fail "a refused export changed OUT"

# An OUT no export-web wrote is not ours to overwrite.
mkdir "$tmp/other" && echo x > "$tmp/other/index.html"
# Issue 44: without --overwrite the refusal does not advise --overwrite for it (that refuses too).
if "$panoptes" export-web "$tmp/A" "$tmp/other" 2>"$tmp/err" >/dev/null; then fail "wrote into a foreign OUT"; fi
grep -q -- "--overwrite" "$tmp/err" && { cat "$tmp/err"; fail "advises --overwrite for a foreign OUT"; }
grep -q "not written by export-web" "$tmp/err" || { cat "$tmp/err"; fail "unclear refusal of a foreign OUT"; }
# ... while for an earlier export it does.
if "$panoptes" export-web "$tmp/A" "$tmp/site" 2>"$tmp/err" >/dev/null; then fail "replaced an export without --overwrite"; fi
grep -q -- "use --overwrite" "$tmp/err" || { cat "$tmp/err"; fail "no --overwrite advice for an earlier export"; }
if "$panoptes" export-web "$tmp/A" "$tmp/other" --overwrite 2>"$tmp/err" >/dev/null; then fail "overwrote a foreign OUT"; fi
grep -q "panoptes-site" "$tmp/err" || { cat "$tmp/err"; fail "unclear refusal of a foreign OUT"; }
[ "$(cat "$tmp/other/index.html")" = x ] || fail "the foreign index.html changed"

# A failed export (file size limit) leaves no partial tree and no staging directory.
if (ulimit -f 64; "$panoptes" export-web "$tmp/B" "$tmp/site2") 2>"$tmp/err" >/dev/null; then fail "export past ulimit -f succeeded"; fi
[ ! -e "$tmp/site2" ] || fail "a failed export left $tmp/site2"
! ls -A "$tmp" | grep -q "export-web" || fail "a failed export left its staging directory"

# Issue 44: a SIGKILLed export leaves its hidden staging directory beside OUT; the next export into the
# same OUT removes it (this host's, dead process), and keeps a live export's. The leftovers are made as
# a killed run leaves them (a pid that has exited; the same name pattern), so the check is exact.
host=$(hostname | tr './' '__')
sleep 0 & dead=$!; wait "$dead" || true
mkdir -p "$tmp/.site4.export-web.$host.$dead.1/api" && echo '{}' > "$tmp/.site4.export-web.$host.$dead.1/api/database.json"
mkdir "$tmp/.site4.export-web.$host.$$.2"  # this shell's pid: alive
"$panoptes" export-web "$tmp/A" "$tmp/site4" >/dev/null || fail "export beside a dead staging directory failed"
[ ! -e "$tmp/.site4.export-web.$host.$dead.1" ] || fail "a killed export's staging directory was left beside OUT"
[ -d "$tmp/.site4.export-web.$host.$$.2" ] || fail "a live export's staging directory was removed"
rmdir "$tmp/.site4.export-web.$host.$$.2"
# And a real kill: whatever it left, the next export leaves no staging directory of a dead process.
"$panoptes" synth-db "$tmp/K" --cameras 24 --tasks 2 --frames 40 --size 128x128 --gop 1 >/dev/null
"$panoptes" export-web "$tmp/K" "$tmp/site5" >/dev/null 2>&1 & victim=$!
sleep 0.3; kill -9 "$victim" 2>/dev/null || true; wait "$victim" 2>/dev/null || true
rm -rf "$tmp/site5"
"$panoptes" export-web "$tmp/A" "$tmp/site5" >/dev/null || fail "export after a killed one failed"
! ls -A "$tmp" | grep -q "^\.site5\.export-web" || fail "a killed export's staging directory is still there: $(ls -A "$tmp")"

# OUT named with a trailing slash, existing and empty (the README's `export-web out/demo site/`): the
# staging directory goes beside it, not inside it.
mkdir "$tmp/site3"
"$panoptes" export-web "$tmp/A" "$tmp/site3/" >/dev/null || fail "export into an empty OUT/ failed"
[ -f "$tmp/site3/index.html" ] && [ -f "$tmp/site3/api/database.json" ] || fail "OUT/ holds no site"

# Row 12: past `ulimit -f` a writer says so in one line (no SIGXFSZ core dump).
set +e
(ulimit -f 8; "$panoptes" synth-db "$tmp/big" --cameras 2 --tasks 1 --frames 30 --size 256x256 --gop 1 >/dev/null 2>"$tmp/err")
status=$?
set -e
[ "$status" = 1 ] || { cat "$tmp/err"; fail "exit status $status past ulimit -f, expected 1"; }
grep -q "^panoptes: error: .*file size limit" "$tmp/err" || { cat "$tmp/err"; fail "no file size limit message"; }
[ "$(wc -l < "$tmp/err")" = 1 ] || { cat "$tmp/err"; fail "more than one error line"; }
echo "export_web: ok"
