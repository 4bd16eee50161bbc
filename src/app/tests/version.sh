#!/usr/bin/env bash
# The version lives in one place, CMakeLists.txt's project(VERSION), generated into core/version.hpp:
# `panoptes version`, `--version`, a manifest's writer version, the C API, Python's __version__ and
# web/package.json must all say it, and no source file may hold the string itself.
set -euo pipefail
panoptes=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
build=$(cd "$(dirname "$panoptes")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "version.sh: $*"; exit 1; }

v=$(sed -n 's/^project(Panoptes VERSION \([0-9][0-9.]*\) .*/\1/p' "$root/CMakeLists.txt")
[[ $v =~ ^[0-9]+\.[0-9]+\.[0-9]+$ ]] || fail "no project(Panoptes VERSION x.y.z) in CMakeLists.txt (got '$v')"

got=$("$panoptes" version | head -1)
[ "$got" = "panoptes $v" ] || fail "'panoptes version' says '$got'; CMakeLists.txt says $v"
got=$("$panoptes" --version)
[ "$got" = "panoptes $v" ] || fail "'panoptes --version' says '$got'; CMakeLists.txt says $v"

"$panoptes" synth-db "$tmp/db" --cameras 2 --tasks 1 --frames 2 --size 64x64 --gop 2 >/dev/null
grep -qE "\"version\": ?\"$v\"" "$tmp/db/panoptes.json" || fail "panoptes.json (manifest) writer version is not $v:
$(grep -n '"version"' "$tmp/db/panoptes.json")"

got=$(/usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['version'])" "$root/web/package.json")
[ "$got" = "$v" ] || fail "web/package.json says version $got; CMakeLists.txt says $v"

if [ -f "$build/lib/libpanoptes.so" ]; then
  got=$(/usr/bin/python3 -c "import ctypes, sys; l = ctypes.CDLL(sys.argv[1]); l.panoptes_version.restype = ctypes.c_char_p; print(l.panoptes_version().decode())" "$build/lib/libpanoptes.so")
  [ "$got" = "$v" ] || fail "the C API's panoptes_version() says $got; CMakeLists.txt says $v"
else
  echo "version.sh: $build/lib/libpanoptes.so not built; C API not checked"
fi
if ls "$build"/python/panoptes/_panoptes*.so >/dev/null 2>&1; then
  got=$(PYTHONPATH="$build/python" /usr/bin/python3 -c "import panoptes; print(panoptes.__version__)")
  [ "$got" = "$v" ] || fail "Python's panoptes.__version__ is $got; CMakeLists.txt says $v"
else
  echo "version.sh: the Python package is not built; panoptes.__version__ not checked"
fi

# No copy of the string in the sources (test fixtures that spell a version of their own are data).
copies=$(grep -rnF "\"$v\"" "$root/src" "$root/include" "$root/bench" --include='*.cpp' --include='*.hpp' \
         --include='*.h' --include='*.py' --include='*.js' --include='*.f90' | grep -v '/test_support.hpp:' || true)
[ -z "$copies" ] || fail "the version is spelled out in the sources (use panoptes::kVersion / core/version.hpp):
$copies"
echo "version.sh: $v everywhere"
