#!/usr/bin/env bash
# The demo from a fresh Debian 12 machine: install packages, build, run mini_md's void-impact
# scene on 2 MPI ranks with Lantern rendering in situ, and say where the images went.
# Usage: bash examples/run_demo.sh [output-dir]   (default: out/demo)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=$(mkdir -p "${1:-$root/out/demo}" && cd "${1:-$root/out/demo}" && pwd)
bash "$root/.ci/install-dependencies"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release > "$out/cmake.log"
cmake --build "$root/build" -j "$(nproc)" --target mini_md >> "$out/cmake.log"
mpi=(mpiexec --oversubscribe -n 2)
[ "$(id -u)" = 0 ] && mpi+=(--allow-run-as-root)
cd "$out"  # config/void_impact.yaml writes relative to the working directory
LP_NUM_THREADS=1 "${mpi[@]}" "$root/build/mini_md/mini_md" --scene void_impact --cells 30 \
  --steps 800 --thermo 200 --render "$root/config/void_impact.yaml"
echo
echo "Images:  $out/void_impact/  ($(ls "$out"/void_impact/*.png | wc -l) PNG files, two scenes every 100 steps)"
echo "Stats:   $out/void_impact/stats.jsonl  (one JSON line per rendered step)"
