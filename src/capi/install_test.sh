#!/usr/bin/env bash
# The installed package, used from outside as a user's project would: `cmake --install` into a
# temporary prefix, then the C, C++ and Fortran heat examples built OUT OF TREE against it, once with
# CMake (find_package(Panoptes); the C++ one includes <mpi.h> and links Panoptes::panoptes alone) and
# once with pkg-config; the Fortran one also from the installed module SOURCE
# (share/panoptes/fortran/panoptes.f90), as users of other Fortran compilers build it. The CMake builds
# run with 1 and 2 MPI ranks, the others with 2 (the CI budget: each run costs an MPI start-up), and
# every database is checked with the installed `panoptes info`. Also: only the C API is exported from
# libpanoptes.so, the installed executable runs without LD_LIBRARY_PATH, and the installed Python
# package imports and reads a frame.
#   install_test.sh BUILD_DIR WORK_DIR [build|run|all]
# The phases (ctest runs them as two tests, capi.install_build and capi.install): "build" installs and
# compiles every example into WORK_DIR, "run" runs and checks them there (MPI: it takes turns with the
# other MPI tests; the compiles need not), "all" (the default) does both.
set -euo pipefail
build=$(cd "$1" && pwd)
work=$2
phase=${3:-all}
case "$phase" in build|run|all) ;; *) echo "install_test: phase '$phase' (expected build, run or all)" >&2; exit 2 ;; esac
if [ "$phase" != run ]; then
  rm -rf "$work"
  mkdir -p "$work"
fi
[ -d "$work" ] || { echo "install_test: $work missing: run the build phase first" >&2; exit 1; }
work=$(cd "$work" && pwd)
prefix=$work/prefix
unset LD_LIBRARY_PATH PKG_CONFIG_PATH CMAKE_PREFIX_PATH || true

fail() { echo "install_test: FAIL: $*" >&2; exit 1; }
start=$(date +%s%N)
step() { local ms=$((($(date +%s%N) - start) / 1000000)); printf '== [%d.%d s] %s\n' $((ms / 1000)) $((ms % 1000 / 100)) "$*"; }

if [ "$phase" != run ]; then
  step "cmake --install $build --prefix $prefix"
  cmake --install "$build" --prefix "$prefix" >"$work/install.log" || { cat "$work/install.log"; fail "cmake --install"; }
fi
libdir=$(dirname "$(find "$prefix" -name 'libpanoptes.so' | head -1)")
[ -n "$libdir" ] && [ -d "$libdir" ] || fail "no libpanoptes.so installed"
for f in bin/panoptes include/panoptes.h include/panoptes.hpp include/panoptes/fortran/panoptes.mod \
         share/panoptes/fortran/panoptes.f90; do
  [ -e "$prefix/$f" ] || fail "$f not installed"
done
for f in libpanoptes_fortran.a cmake/Panoptes/PanoptesConfig.cmake cmake/Panoptes/PanoptesConfigVersion.cmake \
         cmake/Panoptes/PanoptesTargets.cmake pkgconfig/panoptes.pc pkgconfig/panoptes-fortran.pc; do
  [ -e "$libdir/$f" ] || fail "$libdir/$f not installed"
done
doc=$(find "$prefix/share/doc" -maxdepth 1 -mindepth 1 -type d | head -1)
for f in README.md docs/formats.md docs/instrumenting.md examples/heat_c/heat.c examples/heat_c/CMakeLists.txt \
         examples/heat_cpp/heat.cpp examples/heat_cpp/CMakeLists.txt \
         examples/heat_fortran/heat.f90 examples/heat_fortran/CMakeLists.txt; do
  [ -e "$doc/$f" ] || fail "$doc/$f not installed"
done
grep "$prefix" "$libdir/pkgconfig/panoptes.pc" >/dev/null || fail "panoptes.pc does not name the install prefix"

step "libpanoptes.so exports the C API only"
exported=$(nm -D --defined-only "$libdir/libpanoptes.so" | awk '{print $3}' | grep -v '^panoptes_' || true)
[ -z "$exported" ] || fail "libpanoptes.so exports more than panoptes_*: $(echo "$exported" | head -5 | tr '\n' ' ')"
nm -D --defined-only "$libdir/libpanoptes.so" | grep ' panoptes_create$' >/dev/null || fail "panoptes_create not exported"

step "installed panoptes runs from another directory without LD_LIBRARY_PATH"
(cd / && "$prefix/bin/panoptes" --help >/dev/null) || fail "installed panoptes --help"

ex=$doc/examples
steps=20   # snapshots at steps 0, 10, 20 (heat.toml: every_steps = 10)
run_and_check() {  # name binary example ranks...
  [ "$phase" != build ] || return 0
  local name=$1 bin=$2 example=$3
  shift 3
  for np in "$@"; do
    local dir=$work/run_${name}_np$np
    mkdir -p "$dir"
    (cd "$dir" && mpiexec --oversubscribe -np "$np" "$bin" "$ex/$example/heat.toml" $steps >run.log 2>&1) ||
      { cat "$dir/run.log"; fail "$name with $np ranks"; }
    local out
    out=$(cd / && "$prefix/bin/panoptes" info --json "$dir/${example}_db") || fail "panoptes info on $name np $np: $out"
    grep -E '"status": *"complete"' <<<"$out" >/dev/null || fail "$name np $np: database not complete: $out"
    grep -E '"frames": *3' <<<"$out" >/dev/null || fail "$name np $np: expected 3 frames: $out"
    echo "$name, $np rank(s): database complete, 3 frames"
  done
}

step "CMake: find_package(Panoptes) builds of the examples"
for example in heat_c heat_cpp heat_fortran; do
  [ "$phase" != run ] || { run_and_check "cmake_$example" "$work/cmake_$example/$example" $example 1 2; continue; }
  cmake -S "$ex/$example" -B "$work/cmake_$example" -G Ninja -DCMAKE_BUILD_TYPE=Release \
        -DCMAKE_PREFIX_PATH="$prefix" >"$work/cmake_$example.log" 2>&1 ||
    { cat "$work/cmake_$example.log"; fail "configure $example against the install"; }
  cmake --build "$work/cmake_$example" >>"$work/cmake_$example.log" 2>&1 ||
    { cat "$work/cmake_$example.log"; fail "build $example against the install"; }
  run_and_check "cmake_$example" "$work/cmake_$example/$example" $example 1 2
done

step "pkg-config builds of the examples"
export PKG_CONFIG_PATH=$libdir/pkgconfig
[ "$phase" = run ] || cc -O2 "$ex/heat_c/heat.c" $(pkg-config --cflags --libs panoptes) -o "$work/pkg_heat_c" ||
  fail "cc heat.c \$(pkg-config --cflags --libs panoptes)"
run_and_check pkg_heat_c "$work/pkg_heat_c" heat_c 2
[ "$phase" = run ] || mpifort -O2 "$ex/heat_fortran/heat.f90" $(pkg-config --cflags --libs panoptes-fortran) -o "$work/pkg_heat_fortran" ||
  fail "mpifort heat.f90 \$(pkg-config --cflags --libs panoptes-fortran)"
run_and_check pkg_heat_fortran "$work/pkg_heat_fortran" heat_fortran 2

# C++ with plain c++ (no MPI wrapper): <mpi.h> in C++ must not leave MPI C++ symbols undefined.
[ "$phase" = run ] || c++ -O2 -std=c++17 "$ex/heat_cpp/heat.cpp" $(pkg-config --cflags --libs panoptes) -o "$work/pkg_heat_cpp" ||
  fail "c++ heat.cpp \$(pkg-config --cflags --libs panoptes)"
run_and_check pkg_heat_cpp "$work/pkg_heat_cpp" heat_cpp 2

step "Fortran module built from the installed source"
mkdir -p "$work/f90src"
[ "$phase" = run ] || (cd "$work/f90src" && mpifort -O2 -c "$prefix/share/panoptes/fortran/panoptes.f90" &&
   mpifort -O2 "$ex/heat_fortran/heat.f90" panoptes.o -L"$libdir" -Wl,-rpath,"$libdir" -lpanoptes -o heat_fortran) ||
  fail "mpifort panoptes.f90 heat.f90 -lpanoptes"
run_and_check src_heat_fortran "$work/f90src/heat_fortran" heat_fortran 2

pydir=$(find "$prefix" -type d -name panoptes -path '*-packages/*' | head -1)
if [ -n "$pydir" ] && [ "$phase" != build ]; then
  step "installed Python package"
  PYTHONPATH=$(dirname "$pydir") /usr/bin/python3 -c "
import sys, panoptes
assert panoptes.__file__.startswith('$prefix'), panoptes.__file__
db = panoptes.open('$work/run_cmake_heat_c_np2/heat_c_db')
f = db.frame(0, 0, 2)
assert f.shape == (96, 96, 3) and f.dtype.name == 'uint8', (f.shape, f.dtype)
print('python:', panoptes.__file__, db.frame_count, 'frames', f.shape)
" || fail "import panoptes from the install"
fi
step "install_test ($phase): OK"
