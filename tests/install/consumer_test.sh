#!/usr/bin/env bash
# Installs the build tree into a scratch prefix, as a new user would, and checks that it works
# from there without LD_LIBRARY_PATH: every installed program answers --help and --version in a
# clean environment (env -i: finding liblantern by its relative RPATH, $ORIGIN/../lib), the
# Python module imports in one, no installed binary names a folder of the build tree, the licence
# is installed and reported by the CMake package, and tests/install/consumer builds against the
# package with find_package(Lantern), runs and writes its image.
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
prefix=$work/prefix
version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build_dir/CMakeCache.txt")
test -n "$version"
# A clean environment: no LD_LIBRARY_PATH, PYTHONPATH or MPI settings from the caller (only a
# sanitized build's runtime options pass, as they are no search path).
clean_env=(env -i "PATH=/usr/bin:/bin" "HOME=$work")
for option in ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS; do
  if [ -n "${!option:-}" ]; then clean_env+=("$option=${!option}"); fi
done
# Every installed program, whatever it is: none may be left out of this test by being new.
programs=("$prefix"/bin/*)
for required in lantern-render mini_md; do
  test -x "$prefix/bin/$required" || { echo "$required is not installed" >&2; exit 1; }
done
for program in "${programs[@]}"; do
  name=$(basename "$program")
  "${clean_env[@]}" "$program" --help > "$work/help.txt" 2> "$work/help.err" || {
    echo "$name --help failed:" >&2; cat "$work/help.err" "$work/help.txt" >&2; exit 1; }
  grep -q "^usage: $name" "$work/help.txt" || {
    echo "$name --help printed no usage line:" >&2; cat "$work/help.txt" >&2; exit 1; }
  "${clean_env[@]}" "$program" --version > "$work/version.txt" 2> "$work/version.err" || {
    echo "$name --version failed:" >&2; cat "$work/version.err" >&2; exit 1; }
  grep -qx "$name (Lantern) $version" "$work/version.txt" || {
    echo "$name --version printed '$(cat "$work/version.txt")', not '$name (Lantern) $version'" >&2
    exit 1
  }
  echo "$(cat "$work/version.txt"): --help and --version without LD_LIBRARY_PATH"
done
# Installed binaries find Lantern's libraries relative to themselves, never in the build tree.
while IFS= read -r -d '' binary; do
  if readelf -h "$binary" > /dev/null 2>&1; then  # an ELF file
    if readelf -d "$binary" | grep -E 'R(UN)?PATH' | grep -qF "$build_dir"; then
      echo "$binary still names the build tree in its RPATH:" >&2
      readelf -d "$binary" | grep -E 'R(UN)?PATH' >&2
      exit 1
    fi
  fi
done < <(find "$prefix" -type f \( -perm -u+x -o -name '*.so*' \) -print0)
# The licence, installed with the package's documentation and named by the package.
test -f "$prefix/share/doc/Lantern/LICENSE"
test -f "$prefix/share/doc/Lantern/CITATION.cff"
consumer_flags=()
if [ -n "$sanitize" ]; then
  consumer_flags=("-DCONSUMER_COMPILE_OPTIONS=-fsanitize=$sanitize;-fno-omit-frame-pointer")
fi
cmake -S "$source_dir" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" "${consumer_flags[@]}" \
  > "$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
grep -q "Lantern_GL_BACKENDS=" "$work/configure.log"  # the package reports its GL back ends
grep "Lantern_GL_BACKENDS=" "$work/configure.log"
grep -qx -- "-- Lantern_LICENSE=BSD-3-Clause" "$work/configure.log" || {
  echo "the installed package does not report Lantern_LICENSE=BSD-3-Clause" >&2; exit 1; }
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
  (cd "$work" && "${clean_env[@]}" PYTHONPATH="$python_dir" "$python" -c \
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
