#!/usr/bin/env bash
# The image-hash check: renders mini_md's void_impact with config/void_impact.yaml at 2 ranks and
# every config/*.yaml at 1 and 3 ranks, and prints one "sha256  file" line per image written.
# A change that must not move pixels (a refactor, a new feature that is off by default) prints the
# same lines before and after:
#   bash tests/image_hashes.sh build-before > before.txt
#   bash tests/image_hashes.sh build-after > after.txt && diff before.txt after.txt
# Usage: bash tests/image_hashes.sh [build-dir [work-dir]]  (default: build, a fresh temporary dir)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
work=${2:-$(mktemp -d)}
mkdir -p "$work"
mini_md=$build/mini_md/mini_md
mpi=(mpiexec --oversubscribe)
[ "$(id -u)" = 0 ] && mpi+=(--allow-run-as-root)
export LP_NUM_THREADS=1

run() {  # run NAME RANKS CONFIG mini_md-options...
  local name=$1 ranks=$2 config=$3
  shift 3
  mkdir -p "$work/$name"
  (cd "$work/$name" &&
    "${mpi[@]}" -n "$ranks" "$mini_md" "$@" --thermo 0 --render "$config" > run.log 2>&1) ||
    { echo "image_hashes: $name failed:" >&2; tail -5 "$work/$name/run.log" >&2; exit 1; }
}

run demo_2 2 "$root/config/void_impact.yaml" --scene void_impact --cells 16 --steps 300
for config in "$root"/config/*.yaml; do
  base=$(basename "$config" .yaml)
  [[ $base == lammps* ]] && continue  # their lammps: section is for lantern-lammps
  [ "$base" = exr_depth ] && continue  # radius: per_particle, which mini_md does not publish
  for ranks in 1 3; do
    run "${base}_$ranks" "$ranks" "$config" --scene void_impact --cells 10 --steps 250
  done
done
cd "$work"
find . -type f \( -name '*.png' -o -name '*.jpg' -o -name '*.tif' -o -name '*.exr' \
  -o -name '*.mp4' -o -name '*.mkv' \) | LC_ALL=C sort | xargs sha256sum
