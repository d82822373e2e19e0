#!/usr/bin/env bash
# Installs the build tree into a scratch prefix, builds tests/install/consumer against it with
# find_package(Lantern), runs it and checks the image it wrote.
# Usage: consumer_test.sh BUILD_DIR CONSUMER_SOURCE_DIR [SANITIZERS]
#   SANITIZERS: the build's LANTERN_SANITIZE (e.g. address,undefined). The consumer is compiled
#   with them but given no link flag: the installed package must report them and bring their
#   runtime (an ASan liblantern refuses to load into a program without it).
set -euo pipefail
build_dir=$1
source_dir=$2
sanitize=${3:-}  # the sanitizers of the build (empty: none)
python=${4:-}    # the interpreter the Python module was built for (empty: not built or sanitized)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"
test -f "$work/prefix/include/lantern/lantern.h"
consumer_flags=()
if [ -n "$sanitize" ]; then
  consumer_flags=("-DCONSUMER_COMPILE_OPTIONS=-fsanitize=$sanitize;-fno-omit-frame-pointer")
fi
cmake -S "$source_dir" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" "${consumer_flags[@]}" \
  > "$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
grep -q "Lantern_GL_BACKENDS=" "$work/configure.log"  # the package reports its GL back ends
grep "Lantern_GL_BACKENDS=" "$work/configure.log"
grep -qx -- "-- Lantern_SANITIZE=$sanitize" "$work/configure.log" || {
  echo "the installed package does not report Lantern_SANITIZE=$sanitize:" >&2
  grep "Lantern_SANITIZE" "$work/configure.log" >&2 || true
  exit 1
}
"$work/build/consumer" "$work"
# The bindings: the installed Python module imports (finding liblantern by its RPATH) and the
# Fortran module file is where the package says.
python_dir=$(sed -n 's/^-- Lantern_PYTHON_DIR=//p' "$work/configure.log")
fortran_dir=$(sed -n 's/^-- Lantern_Fortran_MODULE_DIR=//p' "$work/configure.log")
if [ -n "$python" ]; then
  test -n "$python_dir"
  (cd "$work" && PYTHONPATH="$python_dir" "$python" -c \
    'import lantern, sys; assert lantern.__file__.startswith(sys.argv[1]), lantern.__file__; print("python: lantern", lantern.__version__, "from", lantern.__file__)' "$python_dir")
  # The package's pure-Python modules are installed with it (each imports its program lazily or
  # at import: lantern.render needs MDAnalysis only to run, lantern.openmm needs OpenMM).
  (cd "$work" && PYTHONPATH="$python_dir" "$python" -c 'import lantern.render')
  test -f "$python_dir/lantern/openmm.py"
fi
test -x "$work/prefix/bin/lantern-imd"
if [ -n "$fortran_dir" ]; then test -f "$fortran_dir/lantern.mod"; echo "fortran: $fortran_dir/lantern.mod"; fi
test -s "$work/consumer.png"
echo "consumer test passed"
