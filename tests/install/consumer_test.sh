#!/usr/bin/env bash
# Installs the build tree into a scratch prefix, builds tests/install/consumer against it with
# find_package(Lantern), runs it and checks the image it wrote.
set -euo pipefail
build_dir=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"
test -f "$work/prefix/include/lantern/lantern.h"
cmake -S "$source_dir" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log"
cmake --build "$work/build" > "$work/build.log"
grep -q "Lantern_GL_BACKENDS=" "$work/configure.log"  # the package reports its GL back ends
grep "Lantern_GL_BACKENDS=" "$work/configure.log"
"$work/build/consumer" "$work"
test -s "$work/consumer.png"
echo "consumer test passed"
