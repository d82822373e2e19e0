#!/usr/bin/env bash
# The demo from a fresh Debian 12 machine: install packages, build, run mini_md's void-impact
# scene on 2 MPI ranks with Lantern rendering in situ (stills, then a movie), and say where the
# images and the movie went.
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
# The movie: the same run again with config/demo_movie.yaml (legend, label, box, 4 samples,
# screen AO, outlines, an orbiting camera), encoded while the simulation steps. It needs the movie
# and text libraries, which .ci/install-dependencies installs.
LP_NUM_THREADS=1 "${mpi[@]}" "$root/build/mini_md/mini_md" --scene void_impact --cells 30 \
  --steps 800 --thermo 200 --render "$root/config/demo_movie.yaml"
echo
echo "Movie:   $out/void_impact/demo.mp4  (81 frames, 24 fps: steps 0, 10, ..., 800)"
echo "Images:  $out/void_impact/  ($(ls "$out"/void_impact/*.png | wc -l) PNG files, two scenes every 100 steps)"
echo "Stats:   $out/void_impact/stats.jsonl  (one JSON line per rendered step)"
