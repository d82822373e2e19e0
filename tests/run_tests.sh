#!/usr/bin/env bash
# The whole test suite from a fresh Debian 12 machine: install packages, build, run ctest.
# Usage: bash tests/run_tests.sh [build-dir [cmake options...]]   (default: build)
#   e.g. bash tests/run_tests.sh build-egl-only -DLANTERN_WITH_OSMESA=OFF
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
shift || true
bash "$root/.ci/install-dependencies"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$build" -j "$(nproc)"
# llvmpipe threads: tests set their own; MPI tests oversubscribe the two cores.
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 900
