#!/usr/bin/env bash
# `panoptes serve` and `panoptes export-web` from the command line: startup line, raw HTTP requests
# (bash /dev/tcp, so paths go out exactly as written: no client normalizes "..") for escapes, the
# token, byte ranges; a busy port; Ctrl+C; export layout and refusals.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
server=""
trap '[ -n "$server" ] && kill "$server" 2>/dev/null; rm -rf "$tmp"' EXIT

"$panoptes" synth-db "$tmp/db" --cameras 3 --tasks 2 --frames 4 --size 64x48 >/dev/null
echo "TOP-SECRET" > "$tmp/secret.txt"
ln -s "$tmp/secret.txt" "$tmp/db/movies/leak.mp4"

if "$panoptes" serve "$tmp/db" --token 'a;b' 2>"$tmp/err"; then echo "accepted a token with ';'"; exit 1; fi
grep "^panoptes: error: --token" "$tmp/err" >/dev/null

# Not a database: one error line, non-zero exit.
if "$panoptes" serve "$tmp" --port 0 2>"$tmp/err"; then echo "served a directory without a database"; exit 1; fi
grep "^panoptes: error: .*panoptes.json" "$tmp/err" >/dev/null || { cat "$tmp/err"; exit 1; }

"$panoptes" serve "$tmp/db" --port 0 --token abc123 > "$tmp/log" 2>&1 &
server=$!
port=""
for _ in $(seq 100); do
  port=$(sed -n 's|^serving .* at http://127.0.0.1:\([0-9]*\)/?token=abc123$|\1|p' "$tmp/log")
  [ -n "$port" ] && break
  sleep 0.1
done
[ -n "$port" ] || { echo "no startup line"; cat "$tmp/log"; exit 1; }

# request PATH [HEADER...]: prints the raw response (headers + body).
request() {
  local path=$1; shift
  exec 3<>"/dev/tcp/127.0.0.1/$port"
  { printf 'GET %s HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n' "$path"
    for h in "$@"; do printf '%s\r\n' "$h"; done
    printf '\r\n'; } >&3
  cat <&3
  exec 3<&-
}
# awk reads to the end: `head -1` closing the pipe early made `request` die of SIGPIPE under pipefail
# now and then (the test's old flake).
status() { request "$@" | awk 'NR == 1 {print $2}'; }
auth="Authorization: Bearer abc123"

[ "$(status /api/database.json)" = 401 ] || { echo "no token accepted"; exit 1; }
[ "$(status /api/database.json "Authorization: Bearer abc12")" = 401 ] || { echo "wrong token accepted"; exit 1; }
[ "$(status "/api/database.json?token=abc123")" = 200 ] || { echo "query token refused"; exit 1; }
[ "$(status /api/database.json "$auth")" = 200 ] || { echo "bearer token refused"; exit 1; }
for path in /db/../secret.txt /db/%2e%2e/secret.txt /db/movies/%2E%2E/%2E%2E/secret.txt /db/..%2fsecret.txt \
            /db/movies/leak.mp4 /../secret.txt /%2e%2e/%2e%2e/etc/passwd /db/.panoptes.lock; do
  response=$(request "$path" "$auth")
  code=$(echo "$response" | awk 'NR == 1 {print $2}')
  if [ "$code" = 200 ] || [ "$code" = 206 ] || echo "$response" | grep TOP-SECRET >/dev/null; then
    echo "escape served: $path -> $code"; exit 1
  fi
done
response=$(request /db/movies/c1/t1.mp4 "$auth" "Range: bytes=4-11")
echo "$response" | awk 'NR == 1' | grep " 206 " >/dev/null || { echo "no 206 for a range"; exit 1; }
echo "$response" | grep -i "^Content-Range: bytes 4-11/" >/dev/null || { echo "no Content-Range"; exit 1; }
[ "$(request /db/movies/c1/t1.mp4 "$auth" "Range: bytes=4-11" | tail -c 8 | od -An -tx1)" = \
  "$(dd if="$tmp/db/movies/c1/t1.mp4" bs=1 skip=4 count=8 2>/dev/null | od -An -tx1)" ] || { echo "wrong range bytes"; exit 1; }
grep "GET /db/movies/leak.mp4 404 refused: resolves outside" "$tmp/log" >/dev/null || { echo "no refusal log line"; cat "$tmp/log"; exit 1; }

# A second server on the same port fails clearly.
if "$panoptes" serve "$tmp/db" --port "$port" 2>"$tmp/err" >/dev/null; then echo "port shared"; exit 1; fi
grep "^panoptes: error: cannot listen on 127.0.0.1:$port" "$tmp/err" >/dev/null || { cat "$tmp/err"; exit 1; }

# Ctrl+C while clients hold connections (issue 31: it waited for every thread, for ever behind a
# looping indexer): a slow one mid-request-line, one mid-headers, one kept alive and idle.
exec 5<>"/dev/tcp/127.0.0.1/$port" 6<>"/dev/tcp/127.0.0.1/$port" 7<>"/dev/tcp/127.0.0.1/$port"
printf 'GET /db/mov' >&5
printf 'GET /api/database.json HTTP/1.1\r\nHost: x\r\n' >&6
printf 'GET /api/database.json HTTP/1.1\r\nHost: x\r\n%s\r\n\r\n' "$auth" >&7
sleep 0.3
start=$(date +%s%N)
kill -INT "$server"
wait "$server" || { echo "serve exited non-zero after SIGINT"; exit 1; }
server=""
exec 5<&- 6<&- 7<&-
took_ms=$((($(date +%s%N) - start) / 1000000))
((took_ms < 3000)) || { echo "Ctrl+C took $took_ms ms with clients connected"; exit 1; }
grep "^stopped" "$tmp/log" >/dev/null

# export-web: the static layout; refuses a non-empty OUT; --link links instead of copying.
rm "$tmp/db/movies/c2/t0.mp4"
"$panoptes" export-web "$tmp/db" "$tmp/site" > "$tmp/out"
grep "5 of 6 streams indexed" "$tmp/out" >/dev/null || { cat "$tmp/out"; exit 1; }
for f in index.html player.js vendor/mp4box/mp4box.all.mjs api/database.json api/index/1/1.json db/panoptes.json db/movies/c1/t1.mp4; do
  [ -f "$tmp/site/$f" ] || { echo "export lacks $f"; exit 1; }
done
[ ! -e "$tmp/site/api/index/2/0.json" ] && [ ! -e "$tmp/site/db/movies/leak.mp4" ]
cmp "$tmp/site/db/movies/c1/t1.mp4" "$tmp/db/movies/c1/t1.mp4"
if "$panoptes" export-web "$tmp/db" "$tmp/site" 2>"$tmp/err" >/dev/null; then echo "overwrote a non-empty OUT"; exit 1; fi
grep "holds an earlier export-web (use --overwrite" "$tmp/err" >/dev/null  # issue 44: the advice fits an earlier export
"$panoptes" export-web "$tmp/db" "$tmp/linked" --link >/dev/null
[ -L "$tmp/linked/db" ]
echo "serve: ok"
