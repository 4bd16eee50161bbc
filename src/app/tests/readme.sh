#!/usr/bin/env bash
# CLI test (issue 34): every shell and Python snippet of README.md runs, against a small demo database and
# stand-in files (readme_snippets.py says which, and which few commands cannot run in a test and why).
set -euo pipefail
bin=$(realpath "$1")
here=$(cd "$(dirname "$0")" && pwd)
readme=$here/../../../README.md
[ -f "$readme" ] || { echo "readme.sh: no README.md at $readme"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PYTHONPATH=$(dirname "$(dirname "$bin")")/python${PYTHONPATH:+:$PYTHONPATH}
# One passive OpenMP thread per command: on a busy machine (the suite runs 2 tests at a time) spinning
# threads only take the CPU the working one needs.
export PYTHONDONTWRITEBYTECODE=1 OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
/usr/bin/python3 -u "$here/readme_snippets.py" "$readme" "$bin" "$work"
