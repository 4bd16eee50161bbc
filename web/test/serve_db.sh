# Sourced by every browser test script (browser_test.sh, look_test.sh, legend_test.sh, same_keys.sh):
# the one way they start and stop `panoptes serve`. Needs $panoptes.
#   serve_db DB LOG [SERVE ARGS...]  starts `panoptes serve DB --port 0 ARGS` and sets $served_url once
#                                    it listens. Call it directly, not as url=$(serve_db ...): a command
#                                    substitution is a subshell, whose record of the server is lost (a
#                                    first scripts/test once left 4 servers running that way).
#   serve_db_stop                    stops every server started so, waits for each to end, and fails
#                                    naming any that is still there. Call it from the script's EXIT trap.
# Each server also gets SIGTERM when this shell dies without its trap (a CTest timeout's SIGKILL):
# setpriv's parent-death signal, where util-linux has it.
served_pids=()
served_url=""
serve_db() {
  local db=$1 log=$2
  shift 2
  # The log exists before the server starts: the background job's redirection may run after the first
  # sed below, which (under set -e) would end the test on a missing file.
  : > "$log"
  local launcher=()
  if setpriv --help 2>/dev/null | grep -q -- --pdeathsig; then launcher=(setpriv --pdeathsig TERM --); fi
  "${launcher[@]}" "$panoptes" serve "$db" --port 0 "$@" > "$log" 2>&1 &
  served_pids+=($!)
  served_url=""
  for _ in $(seq 100); do
    served_url=$(sed -n 's/^serving .* at \(http[^ ]*\)$/\1/p' "$log")
    [ -n "$served_url" ] && return 0
    sleep 0.1
  done
  echo "serve $db did not start:" >&2
  cat "$log" >&2
  return 1
}

serve_db_stop() {
  local p left=()
  for p in "${served_pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${served_pids[@]}"; do
    # Up to 10 s to end (a zombie has ended: this shell's wait reaps it); one still running would
    # outlive the test, which is what this stop exists to prevent.
    for _ in $(seq 100); do
      [ -e "/proc/$p" ] && ! grep -q '^State:.*zombie' "/proc/$p/status" 2>/dev/null || break
      sleep 0.1
    done
    if [ -e "/proc/$p" ] && ! grep -q '^State:.*zombie' "/proc/$p/status" 2>/dev/null; then
      left+=("$p")
      kill -9 "$p" 2>/dev/null || true
    fi
    wait "$p" 2>/dev/null || true
  done
  served_pids=()
  if [ ${#left[@]} -gt 0 ]; then
    echo "serve_db_stop: panoptes serve ${left[*]} outlived SIGTERM (killed)" >&2
    return 1
  fi
  return 0
}
