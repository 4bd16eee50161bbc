#!/usr/bin/env bash
# Restart (issue 28): `panoptes run` SIGKILLed after a few snapshots and started again with --resume
# ([output] mode = "resume") gives the same database as the uninterrupted run: every decoded frame of
# every movie (exported as PNG) and every time. The restarted solver starts from step 0, so it repeats
# every snapshot already written: they are skipped, never duplicated. A different configuration is
# refused naming what differs; without resume the existing database is refused naming [output] mode.
set -euo pipefail
bin=$1
tmp=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; rm -rf "$tmp"' EXIT
cd "$tmp"
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fail() { echo "run_resume.sh: $*"; exit 1; }

cat > tiny.toml <<'TOML'
[grid]
nx = 24
ny = 20
nz = 16
h = 100.0
[time]
steps = 600
[medium]
type = "homogeneous"
rho = 2500.0
vp = 4000.0
vs = 2300.0
[boundary]
pml_cells = 4
[[source]]
type = "explosion"
position = [1200.0, 1000.0, 800.0]
m0 = 1.0e15
stf = "ricker"
frequency = 6.0
[output]
dir = "db"
[image]
width = 40
height = 32
[rig]
spec = "fibonacci:3"
[schedule]
every_steps = 50
[[task]]
name = "p"
field = "phi_p"
preset = "p-wave"
[[task]]
name = "s"
field = "phi_s"
preset = "s-wave"
TOML

"$bin" run tiny.toml --out full -q >/dev/null || fail "the uninterrupted run failed"
frames=$(grep -Eo '"frames_written": *[0-9]+' full/panoptes.json | grep -Eo '[0-9]+$')
[ "$frames" -eq 12 ] || fail "the uninterrupted run has $frames frames, expected 12"

# A run killed once its manifest counts 3 snapshots (a real SIGKILL: no handler runs).
"$bin" run tiny.toml --out killed -q >/dev/null 2>killed.err &
pid=$!; pids+=("$pid")
for _ in $(seq 1 1200); do
  grep -E '"frames_written": *([3-9]|1[0-9])' killed/panoptes.json >/dev/null 2>&1 && break
  sleep 0.01
done
kill -9 "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
kept=$(grep -Eo '"frames_written": *[0-9]+' killed/panoptes.json | grep -Eo '[0-9]+$')
[ "$kept" -ge 3 ] && [ "$kept" -lt 12 ] || fail "the killed run kept $kept snapshots (expected 3..11: killed too late?)"

set +e
msg=$("$bin" run tiny.toml --out killed -q 2>&1); rc=$?
set -e
[ "$rc" -ne 0 ] || fail "an existing database was overwritten without --overwrite/--resume"
grep -F '[output] mode' <<<"$msg" >/dev/null || fail "the refusal does not name [output] mode: $msg"
# `run` reads the TOML and has --overwrite / --resume: it names both (issue 44); never a C++ setting.
grep -F -e '--overwrite' <<<"$msg" >/dev/null || fail "the refusal does not name run's --overwrite: $msg"
if grep -F 'WriterOptions' <<<"$msg" >/dev/null; then fail "the refusal names a C++ setting: $msg"; fi

sed 's/^spec = "fibonacci:3"$/spec = "fibonacci:4"/' tiny.toml > other_rig.toml
set +e
msg=$("$bin" run other_rig.toml --out killed --resume -q 2>&1); rc=$?
set -e
[ "$rc" -ne 0 ] || fail "a resume with another rig was accepted"
grep -F 'the rig ([rig]) differs' <<<"$msg" >/dev/null || fail "the refusal does not name the rig: $msg"

"$bin" run tiny.toml --out killed --resume -q >/dev/null || fail "the resumed run failed"
out=$("$bin" info --json killed --decode) || fail "info --decode of the resumed database failed: $out"
grep -E '"status": *"complete"' <<<"$out" >/dev/null || fail "resumed database not complete: $out"
grep -E '"frames": *12\b' <<<"$out" >/dev/null || fail "resumed database does not have 12 frames: $out"

# Issue 42, point 4: the same rerun on the now complete database is refused (it used to print one
# info line, exit 0 and keep the old movies: every snapshot of the rerun was "already written").
set +e
msg=$("$bin" run tiny.toml --out killed --resume -q 2>&1); rc=$?
set -e
[ "$rc" -ne 0 ] || fail "a resume of a complete database was accepted"
grep -F 'holds a complete database' <<<"$msg" >/dev/null && grep -F 'resume_complete = true' <<<"$msg" >/dev/null ||
  fail "the refusal of a complete database does not say so: $msg"
out=$("$bin" info --json killed) || fail "info of the refused database failed: $out"
grep -E '"status": *"complete"' <<<"$out" >/dev/null || fail "the refused resume changed the database: $out"

# Same times, same decoded pictures (the Cinema export decodes every frame of every movie to PNG).
tf=$(tr -d ' \n' < full/panoptes.json | grep -Eo '"times":\[[^]]*\]')
tk=$(tr -d ' \n' < killed/panoptes.json | grep -Eo '"times":\[[^]]*\]')
[ "$tf" = "$tk" ] || fail "times differ: $tf vs $tk"
"$bin" export-cinema full full.cdb >/dev/null 2>&1 || fail "export of the uninterrupted run failed"
"$bin" export-cinema killed killed.cdb >/dev/null 2>&1 || fail "export of the resumed run failed"
n=$(find full.cdb -name '*.png' | wc -l)
[ "$n" -eq $((3 * 2 * 12)) ] || fail "expected 72 exported frames, found $n"
# panoptes-cinema.json carries each database's provenance (command line, creation time, the resume
# mark), which rightly differs; every image and data.csv must not.
diff -r -x panoptes-cinema.json full.cdb killed.cdb >/dev/null ||
  fail "the resumed run's frames differ from the uninterrupted run's: $(diff -rq -x panoptes-cinema.json full.cdb killed.cdb | head -3)"
echo "run_resume.sh: ok (killed after $kept of 12 snapshots; $n frames identical)"
