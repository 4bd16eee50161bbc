#!/usr/bin/env bash
# Every subcommand answers --help with exit 0, and a bad subcommand fails with a message.
set -euo pipefail
panoptes=$1
"$panoptes" --help | grep "Panoptes" >/dev/null
"$panoptes" --version | grep "panoptes" >/dev/null
for sub in $("$panoptes" --help | awk '/^SUBCOMMANDS:/{f=1;next} f&&NF{print $1}'); do
  "$panoptes" "$sub" --help >/dev/null || { echo "'$sub --help' failed"; exit 1; }
done
if "$panoptes" no-such-command 2>/dev/null; then echo "unknown subcommand accepted"; exit 1; fi
# The three messages of issue 34, each one clear line and status 1: a mistyped command, a word given for
# a number, a CRF out of range (its prefix was doubled: "manifest: video settings: video settings: ...").
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
expect_error() {  # expect_error EXPECTED-LINE COMMAND...
  local expected=$1 status=0
  shift
  "$@" > "$tmp/out" 2> "$tmp/err" || status=$?
  [ "$status" = 1 ] || { echo "'$*' exited with $status, expected 1"; exit 1; }
  [ "$(wc -l < "$tmp/err")" = 1 ] || { echo "'$*' printed more than one line:"; cat "$tmp/err"; exit 1; }
  grep -qxF "$expected" "$tmp/err" || { echo "'$*' says: $(cat "$tmp/err")"; echo "expected: $expected"; exit 1; }
}
expect_error 'panoptes: error: unknown command "pley"; did you mean "play"? (see `panoptes --help`)' "$panoptes" pley out/demo
expect_error 'panoptes: error: --sample-distance: "abc" is not a number (e.g. 0.5) (see `panoptes render --help`)' \
  "$panoptes" render v.npy --sample-distance abc --out "$tmp/db"
expect_error 'panoptes: error: --frames: "1.5" is not an integer (e.g. 3) (see `panoptes synth-db --help`)' \
  "$panoptes" synth-db "$tmp/db" --frames 1.5
/usr/bin/python3 -c "import numpy as np; np.save('$tmp/v.npy', np.ones((4, 4, 4), 'f4'))"
expect_error "panoptes: error: --crf 99: expected an x264 quality 0..51" \
  "$panoptes" render "$tmp/v.npy" --rig fibonacci:2 --size 32x32 --crf 99 --out "$tmp/db"
echo "help: ok"
