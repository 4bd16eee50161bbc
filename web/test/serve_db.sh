# Sourced by the browser test scripts (look_test.sh, same_keys.sh): needs $panoptes and a pids array,
# which the caller's cleanup kills.
# serve_db DB LOG: starts `panoptes serve DB` on a free port and prints its URL once it listens.
serve_db() {
  : > "$2"
  "$panoptes" serve "$1" --port 0 --quiet > "$2" 2>&1 &
  pids+=($!)
  local u=""
  for _ in $(seq 100); do
    u=$(sed -n 's/^serving .* at \(http[^ ]*\)$/\1/p' "$2")
    [ -n "$u" ] && { echo "$u"; return 0; }
    sleep 0.1
  done
  echo "serve $1 did not start:" >&2; cat "$2" >&2; return 1
}
