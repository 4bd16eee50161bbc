#!/usr/bin/env bash
# Killed and interrupted runs (issue #15): `panoptes run` is SIGKILLed at 10 random moments of a tiny
# run; after each, `panoptes info --decode` must find every snapshot the manifest counts decodable in
# every movie. SIGINT and SIGTERM must finish or abandon the current snapshot, leave the database
# `interrupted` (stored so, lock removed) and exit with 128 + signal within a few seconds.
set -euo pipefail
bin=$1
tmp=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; rm -rf "$tmp"' EXIT
cd "$tmp"
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fail() { echo "kill_run.sh: $*"; exit 1; }

cat > tiny.toml <<'TOML'
[grid]
nx = 24
ny = 20
nz = 16
h = 100.0
[time]
steps = 160
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
every_steps = 6
[[task]]
name = "p"
field = "phi_p"
preset = "p-wave"
[[task]]
name = "s"
field = "phi_s"
preset = "s-wave"
[video]
gop = 4
TOML

# The run's length on this machine, to spread the kill moments over it.
t0=$(date +%s%N)
"$bin" run tiny.toml --out full -q >/dev/null 2>&1 || fail "the tiny run failed"
run_ms=$(( ($(date +%s%N) - t0) / 1000000 ))
"$bin" info full --decode >/dev/null || fail "the complete run does not decode"

RANDOM=15  # reproducible kill moments
for i in $(seq 1 10); do
  delay_ms=$(( 50 + RANDOM % (run_ms > 100 ? run_ms : 100) ))
  "$bin" run tiny.toml --out "k$i" -q >/dev/null 2>"k$i.err" &
  pid=$!; pids+=("$pid")
  sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))"
  kill -9 "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  [ -e "k$i/panoptes.json" ] || continue  # killed before the database existed
  set +e
  out=$("$bin" info "k$i" --decode --json 2>&1); rc=$?
  set -e
  [ "$rc" -eq 0 ] || fail "kill $i after ${delay_ms} ms: info --decode exit $rc: $(grep -E '"(message|status|frames)"' <<<"$out")"
  grep -E '"status": "(interrupted|complete)"' <<<"$out" >/dev/null || fail "kill $i: status: $out"
done

# Ten times the steps: the tiny run can finish between its first checkpoint and the signal (seen once
# at load 15 after its frames got cheaper), and then exits 0 instead of being interrupted.
sed 's/^steps = 160$/steps = 1600/' tiny.toml > long.toml
for sig in INT TERM; do
  "$bin" run long.toml --out "s$sig" -q >/dev/null 2>"s$sig.err" &
  pid=$!; pids+=("$pid")
  # Wait for the first checkpoint, then signal.
  for _ in $(seq 1 400); do
    grep -E '"frames_written": *[1-9]' "s$sig/panoptes.json" >/dev/null 2>&1 && break
    sleep 0.05
  done
  t0=$(date +%s%N)
  kill -s "$sig" "$pid"
  set +e
  wait "$pid"; rc=$?
  set -e
  ms=$(( ($(date +%s%N) - t0) / 1000000 ))
  want=$([ "$sig" = INT ] && echo 130 || echo 143)
  [ "$rc" -eq "$want" ] || fail "SIG$sig: exit status $rc, expected $want; stderr: $(cat "s$sig.err")"
  [ "$ms" -lt 5000 ] || fail "SIG$sig: took $ms ms to stop"
  grep -F "interrupted" "s$sig.err" >/dev/null || fail "SIG$sig: no message: $(cat "s$sig.err")"
  [ ! -e "s$sig/.panoptes.lock" ] || fail "SIG$sig: the lock was left behind"
  out=$("$bin" info "s$sig" --decode --json) || fail "SIG$sig: info --decode failed: $out"
  grep -F '"stored_status": "interrupted"' <<<"$out" >/dev/null || fail "SIG$sig: not stored as interrupted: $out"
  grep -E '"frames": *[1-9]' <<<"$out" >/dev/null || fail "SIG$sig: no frames kept: $out"
done
echo "kill_run.sh: ok (run ${run_ms} ms)"
