# Sourced by the browser tests: player_dir PANOPTES TMP sets PANOPTES_WEB_DIR to the built player's
# files, or, when that build has no keys.json yet (written by serve / export-web once issue 30's key
# table export lands), to a copy of them with keys.json generated from src/player/keys.cpp.
player_dir() {
  local panoptes=$1 tmp=$2 here repo share
  here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
  repo=$(cd "$here/../.." && pwd)
  share=$(cd "$(dirname "$panoptes")/../share/panoptes/web" && pwd)
  if [ -f "$share/keys.json" ]; then
    export PANOPTES_WEB_DIR=$share
    return 0
  fi
  cp -r "$share" "$tmp/player"
  node "$here/keys_fixture.mjs" "$repo/src/player/keys.cpp" "$tmp/player/keys.json" >/dev/null
  export PANOPTES_WEB_DIR=$tmp/player
}
