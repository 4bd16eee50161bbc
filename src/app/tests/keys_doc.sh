#!/usr/bin/env bash
# docs/ui.md's key table is `panoptes keys --markdown`, pasted between its markers: this fails when the
# program's table (player/keys.cpp, controls.cpp) and the page differ. Regenerate with the command that
# the failure prints. Also checks the command's other forms and its refusal of a wrong mode.
set -euo pipefail
panoptes=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
doc="$root/docs/ui.md"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "keys_doc.sh: $*"; exit 1; }

begin='<!-- keys:begin'
end='<!-- keys:end -->'
grep -q "^$begin" "$doc" || fail "docs/ui.md has no '$begin ...' marker"
grep -qx "$end" "$doc" || fail "docs/ui.md has no '$end' marker"
sed -n "/^$begin/,/^$end\$/p" "$doc" | sed '1d;$d' > "$tmp/doc.md"
"$panoptes" keys --markdown > "$tmp/program.md"
[ -s "$tmp/program.md" ] || fail "'panoptes keys --markdown' printed nothing"
if ! diff -u "$tmp/doc.md" "$tmp/program.md" > "$tmp/diff"; then
  cat "$tmp/diff"
  fail "docs/ui.md's key table differs from 'panoptes keys --markdown' (above: - page, + program). Regenerate:
  /usr/bin/python3 - <<'PY'
import re, subprocess
p = 'docs/ui.md'; s = open(p).read(); t = subprocess.run(['build/bin/panoptes', 'keys', '--markdown'], capture_output=True, text=True, check=True).stdout
s = re.sub(r'(<!-- keys:begin[^\n]*\n).*?(<!-- keys:end -->)', lambda m: m.group(1) + t + m.group(2), s, flags=re.S); open(p, 'w').write(s)
PY"
fi

# Every binding of the table is a row (keys merge only when action and text are the same).
rows=$(grep -c '^| `' "$tmp/program.md")
[ "$rows" -ge 40 ] || fail "only $rows key rows in 'panoptes keys --markdown'"
# The lattice table says what the arrows do there; the sphere table does not walk.
"$panoptes" keys --markdown --mode lattice | grep -q '^| `Up` | walk forward' || fail "lattice: Up does not walk forward"
"$panoptes" keys --mode sphere | grep -q 'walk' && fail "sphere mode lists a walk"
"$panoptes" keys --json --mode panorama | /usr/bin/python3 -c "import json, sys; j = json.load(sys.stdin); assert j['mode'] == 'panorama' and j['bindings'], j.keys()" \
  || fail "'keys --json --mode panorama' is not the keys.json document with mode panorama"
if "$panoptes" keys --mode street > "$tmp/out" 2>&1; then fail "--mode street was accepted"; fi
grep -q 'expected sphere, panorama or lattice' "$tmp/out" || fail "--mode street: $(cat "$tmp/out")"
[ "$(wc -l < "$tmp/out")" -eq 1 ] || fail "--mode street printed more than one line: $(cat "$tmp/out")"
echo "keys_doc.sh: docs/ui.md's table matches ($rows rows)"
