# Sourced by the browser test scripts (look_test.sh, same_keys.sh): needs $panoptes.
# serve_db DB LOG: starts `panoptes serve DB` on a free port and prints its URL once it listens. Called
# as url=$(serve_db ...), it runs in a subshell, where adding to the caller's pids array is lost (a first
# scripts/test left 4 servers running): the server's pid goes to LOG.pid, which serve_db_stop reads.
serve_db() {
  : > "$2"
  "$panoptes" serve "$1" --port 0 --quiet > "$2" 2>&1 &
  echo $! > "$2.pid"
  local u=""
  for _ in $(seq 100); do
    u=$(sed -n 's/^serving .* at \(http[^ ]*\)$/\1/p' "$2")
    [ -n "$u" ] && { echo "$u"; return 0; }
    sleep 0.1
  done
  echo "serve $1 did not start:" >&2; cat "$2" >&2; return 1
}

# serve_db_stop LOG...: stops the servers serve_db started with these logs (for the caller's cleanup).
serve_db_stop() {
  local f
  for f in "$@"; do [ -f "$f.pid" ] && kill "$(cat "$f.pid")" 2>/dev/null; rm -f "$f.pid"; done
  return 0
}
