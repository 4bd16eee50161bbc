#!/usr/bin/env bash
# One case of the misuse suite (misuse_test.c, issue 42) on 2 ranks; then the database, when the case
# made one, must still be readable by `panoptes info` (an interrupted or complete database, never a
# broken one).   misuse_test.sh MPIEXEC EXE PANOPTES CASE DIR [RANKS (default 2)]
set -uo pipefail
mpiexec=$1 exe=$2 panoptes=$3 case=$4 dir=$5 ranks=${6:-2}
rm -rf "$dir"
"$mpiexec" --oversubscribe -np "$ranks" "$exe" "$case" "$dir"
rc=$?
[ $rc -eq 0 ] || { echo "misuse_test.sh: case $case failed (exit $rc)" >&2; exit 1; }
if [ -f "$dir/panoptes.json" ]; then
  "$panoptes" info "$dir" > "$dir.info" 2>&1 || { cat "$dir.info"; echo "misuse_test.sh: $case left a database info cannot read" >&2; exit 1; }
  echo "misuse_test.sh: $case: the database reads: $(grep -m1 -i 'status' "$dir.info" || head -1 "$dir.info")"
fi
