#!/usr/bin/env bash
# A database from a stranger, through the command line (issue #15): links out of the directory are
# neither written through nor read, FIFOs do not block `info` or `play`, damaged frames are reported
# by `info --decode`, SIGINT stops `synth-db` cleanly, and `steps = 0` is refused before the run.
set -euo pipefail
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
fail() { echo "hostile_db.sh: $*"; exit 1; }
# Runs a command that must fail within 5 s with exit 1 and a one-line error containing $1.
expect_error() {
  local want=$1; shift
  set +e
  timeout 5 "$@" >out.txt 2>err.txt; local rc=$?
  set -e
  [ "$rc" -ne 124 ] || fail "hangs: $*"
  [ "$rc" -eq 1 ] || fail "exit $rc (expected 1): $*; stderr: $(cat err.txt)"
  [ "$(wc -l <err.txt)" -eq 1 ] || fail "not one line: $(cat err.txt)"
  grep -F -- "$want" err.txt >/dev/null || fail "expected '$want' in: $(cat err.txt)"
}
synth() { "$bin" synth-db "$@" --cameras 2 --tasks 1 --frames 3 --size 48x32 >/dev/null; }

# The lock as a link to a file of the user's: never truncated.
echo "precious" >victim
mkdir db1 && ln -s "$tmp/victim" db1/.panoptes.lock
expect_error "symbolic link" "$bin" synth-db db1 --cameras 2 --tasks 1 --frames 3 --size 48x32
[ "$(cat victim)" = "precious" ] || fail "the lock link was written through"

# A planted movies directory link: nothing written outside.
mkdir db2 outside && ln -s "$tmp/outside" db2/movies
expect_error "symbolic link" "$bin" synth-db db2 --cameras 2 --tasks 1 --frames 3 --size 48x32
[ -z "$(ls outside)" ] || fail "movies written through the link: $(ls outside)"

# The manifest as a link to /etc/passwd (not echoed) and to /dev/zero (not read).
synth db3
mv db3/panoptes.json db3/real.json
ln -s /etc/passwd db3/panoptes.json
expect_error "symbolic link" "$bin" info db3
! grep -F "root:" err.txt >/dev/null || fail "/etc/passwd echoed: $(cat err.txt)"
ln -sf /dev/zero db3/panoptes.json
expect_error "symbolic link" "$bin" info db3
expect_error "symbolic link" "$bin" play db3 --headless --no-loop

# FIFOs at the manifest and the camera table: refused at once, not blocking.
rm db3/panoptes.json && mv db3/real.json db3/panoptes.json
table=$(ls db3 | grep '^cameras\..*\.bin$')
mv "db3/$table" table.bin && mkfifo "db3/$table"
expect_error "FIFO" "$bin" info db3
expect_error "FIFO" "$bin" play db3 --headless --no-loop
rm "db3/$table" && mv table.bin "db3/$table"
mv db3/panoptes.json real.json && mkfifo db3/panoptes.json
expect_error "FIFO" "$bin" info db3
rm db3/panoptes.json && mv real.json db3/panoptes.json
# A FIFO at the lock: not a live writer, not a hang.
mkfifo db3/.panoptes.lock
timeout 5 "$bin" info db3 --no-check >/dev/null || fail "info with a FIFO lock"
rm db3/.panoptes.lock

# A damaged P-frame: `info --decode` decodes every frame and names the damaged ones (exit 2).
"$bin" synth-db db4 --cameras 1 --tasks 1 --frames 30 --size 96x64 --gop 30 >/dev/null
python3 - db4/movies/c0/t0.mp4 <<'PY'
import sys
p = sys.argv[1]
b = bytearray(open(p, 'rb').read())
m = b.find(b'mdat')
s = m + (len(b) - m) // 2
for i in range(s, min(s + 24, len(b))):
    b[i] = 0  # zeros: a slice the decoder sees is broken (flipped CABAC bits may decode "validly")
open(p, 'wb').write(b)
PY
set +e
out=$("$bin" info db4 --decode); rc=$?
set -e
[ "$rc" -eq 2 ] || fail "info --decode on a damaged movie: exit $rc: $out"
grep -E "damaged +.*movies/c0/t0.mp4: [0-9]+ of 30 frames damaged" <<<"$out" >/dev/null || fail "damage not listed: $out"
"$bin" info db4 >/dev/null || fail "without --decode the movie opens (the damage is in the pictures)"

# SIGINT during synth-db: exit 130, database interrupted, lock removed.
"$bin" synth-db db5 --cameras 400 --tasks 2 --frames 20 --size 96x64 --threads 1 >/dev/null 2>db5.err &
pid=$!
for _ in $(seq 1 100); do [ -e db5/movies ] && break; sleep 0.05; done
sleep 0.3
kill -INT "$pid"
set +e
wait "$pid"; rc=$?
set -e
[ "$rc" -eq 130 ] || fail "synth-db after SIGINT: exit $rc (expected 130): $(cat db5.err)"
[ ! -e db5/.panoptes.lock ] || fail "synth-db left its lock"
grep -F '"status": "interrupted"' db5/panoptes.json >/dev/null || fail "synth-db: not interrupted: $(head -c 300 db5/panoptes.json)"

# steps = 0 is refused before anything is written.
cat > zero.toml <<'TOML'
[grid]
nx = 16
ny = 16
nz = 16
h = 100.0
[time]
steps = 0
[boundary]
pml_cells = 4
[medium]
type = "homogeneous"
rho = 2500.0
vp = 4000.0
vs = 2300.0
[[source]]
type = "explosion"
position = [800.0, 800.0, 800.0]
m0 = 1.0e15
stf = "ricker"
frequency = 6.0
[output]
dir = "zero_db"
[rig]
spec = "fibonacci:2"
[[task]]
name = "p"
field = "phi_p"
TOML
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 expect_error "time.steps: 0 is out of range" "$bin" run zero.toml
[ ! -e zero_db ] || fail "steps = 0 wrote a database"
echo "hostile_db.sh: ok"
