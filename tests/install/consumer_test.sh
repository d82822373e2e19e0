#!/usr/bin/env bash
# Installs the build tree into a scratch prefix, builds tests/install/consumer against it with
# find_package(Lantern), runs it and checks the image it wrote.
set -euo pipefail
build_dir=$1
source_dir=$2
python=${3:-}  # the interpreter the Python module was built for (empty: not built)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"
test -f "$work/prefix/include/lantern/lantern.h"
cmake -S "$source_dir" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log"
cmake --build "$work/build" > "$work/build.log"
grep -q "Lantern_GL_BACKENDS=" "$work/configure.log"  # the package reports its GL back ends
grep "Lantern_GL_BACKENDS=" "$work/configure.log"
"$work/build/consumer" "$work"
# The bindings: the installed Python module imports (finding liblantern by its RPATH) and the
# Fortran module file is where the package says.
python_dir=$(sed -n 's/^-- Lantern_PYTHON_DIR=//p' "$work/configure.log")
fortran_dir=$(sed -n 's/^-- Lantern_Fortran_MODULE_DIR=//p' "$work/configure.log")
if [ -n "$python" ]; then
  test -n "$python_dir"
  (cd "$work" && PYTHONPATH="$python_dir" "$python" -c \
    'import lantern, sys; assert lantern.__file__.startswith(sys.argv[1]), lantern.__file__; print("python: lantern", lantern.__version__, "from", lantern.__file__)' "$python_dir")
fi
if [ -n "$fortran_dir" ]; then test -f "$fortran_dir/lantern.mod"; echo "fortran: $fortran_dir/lantern.mod"; fi
test -s "$work/consumer.png"
echo "consumer test passed"
