#!/bin/bash
# LAMMPS `dump image` vs Lantern on the same LJ melt, in one run, same image size and cadence.
#
#   tests/bench/lammps_dump_image.sh [BUILD_DIR] [CELLS] [SIZE] [IMAGES] [EVERY] [RANKS]
#   defaults: build-h5, 63 (4*63^3 = 1,000,188 atoms), 1024, 4, 5, 2
#   ASYNC=true: Lantern encodes and writes its PNGs on a background thread (output.asynchronous)
#
# examples/lammps/lammps_lantern runs LAMMPS through its library interface; at every image step it
# renders once through Lantern (lantern_execute on LAMMPS's own x/type arrays) and once through
# LAMMPS's image dump (write_dump all image ... size SIZE SIZE: the same Dump image code as
# `dump image`, PNG in both cases), timing each between barriers on the slowest rank. The table
# gives seconds per image for both and the ratio (target: Lantern >= 10x faster at 1 M atoms).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-h5}
cells=${2:-63} size=${3:-1024} images=${4:-4} every=${5:-5} ranks=${6:-2}
exe=$build/examples/lammps/lammps_lantern
[ -x "$exe" ] || { echo "build lammps_lantern first: cmake --build $build --target lammps_lantern"; exit 1; }
work=$(mktemp -d /tmp/lantern_lammps_bench.XXXXXX)
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
cat > "$work/bench.yaml" <<YAML
# Lantern's side: one 1024x1024 PNG per image step, spheres of diameter 1 (LAMMPS: adiam 1.0).
scenes:
  - name: lj
    width: $size
    height: $size
    radius: 0.5
    output:
      pattern: "$work/lantern_{step:06d}.png"
      asynchronous: ${ASYNC:-false}
stats: "$work/stats.jsonl"
YAML
mpiflags=(--oversubscribe)
[ "$(id -u)" = 0 ] && mpiflags+=(--allow-run-as-root)
steps=$(( (images - 1) * every ))
echo "LJ melt, $((4 * cells * cells * cells)) atoms, ${size}x${size}, $images images every $every steps, $ranks MPI ranks"
OMP_NUM_THREADS=1 mpiexec "${mpiflags[@]}" -n "$ranks" "$exe" "$work/bench.yaml" --cells "$cells" \
  --steps "$steps" --every "$every" --compare-dump-image "$work" --image-size "$size" | tee "$work/out.txt"
ls "$work"/lammps_*.png "$work"/lantern_*.png > /dev/null
summary=$(grep '^images:' "$work/out.txt")
lantern=$(echo "$summary" | sed -E 's/.*lantern: ([0-9.]+) s.*/\1/')
lammps=$(echo "$summary" | sed -E 's/.*dump image: ([0-9.]+) s.*/\1/')
ratio=$(echo "$summary" | sed -E 's/.*ratio: ([0-9.]+)x.*/\1/')
med=$(grep '^median per image:' "$work/out.txt")
lantern_med=$(echo "$med" | sed -E 's/.*lantern: ([0-9.]+) s.*/\1/')
lammps_med=$(echo "$med" | sed -E 's/.*dump image: ([0-9.]+) s.*/\1/')
ratio_med=$(echo "$med" | sed -E 's/.*ratio: ([0-9.]+)x.*/\1/')
atoms=$((4 * cells * cells * cells))
printf '\n| atoms | ranks | image | images | statistic | LAMMPS dump image s/image | Lantern s/image | ratio |\n'
printf '|---|---|---|---|---|---|---|---|\n'
printf '| %d | %d | %dx%d | %d | mean | %s | %s | %sx |\n' "$atoms" "$ranks" "$size" "$size" \
  "$images" "$lammps" "$lantern" "$ratio"
printf '| %d | %d | %dx%d | %d | median | %s | %s | %sx |\n' "$atoms" "$ranks" "$size" "$size" \
  "$images" "$lammps_med" "$lantern_med" "$ratio_med"
