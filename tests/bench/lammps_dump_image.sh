#!/bin/bash
# LAMMPS `dump image` vs Lantern on the same LJ melt, in one run, same image size and cadence.
#
#   tests/bench/lammps_dump_image.sh [BUILD_DIR] [CELLS] [SIZE] [IMAGES] [EVERY] [RANKS]
#   defaults: build-h5, 63 (4*63^3 = 1,000,188 atoms), 1024, 4, 5, 2
#   ASYNC=true: Lantern encodes and writes its PNGs on a background thread (output.asynchronous)
#   SSAO=yes: ambient occlusion on both sides (LAMMPS `ssao yes 4567 0.6`, Lantern
#     `ambient_occlusion: {method: screen}`); run once with and once without to get each side's
#     cost of it
#   SAMPLES=4: Lantern super-samples its images (scene key samples: 1, 4, 16 or 64; default 1)
#   NAPPLY=1: the fix's napply (how often LAMMPS adds the fix's zero forces to the atoms'; default
#     in.lj's, beyond the run): LAMMPS's Modify line then shows what adding them every step costs
#
# lantern-lammps runs examples/lammps/in.lj (the LAMMPS bench melt with `fix viz all external
# pf/callback EVERY 1000000000`) with one more line, `dump img all image EVERY ... size SIZE SIZE
# adiam 1.0`: every EVERY steps LAMMPS draws its image dump and calls Lantern, in the same run.
# Seconds per image: LAMMPS's from its own timing breakdown (the "Output" section, slowest rank,
# over the images after the set-up step: LAMMPS starts its timers after set-up), Lantern's from
# its stats (ms.total of every step after the first, and the median of all steps). The target:
# Lantern >= 10x faster at 1 M atoms.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-h5}
cells=${2:-63} size=${3:-1024} images=${4:-4} every=${5:-5} ranks=${6:-2}
exe=$build/adaptor/lammps/lantern-lammps
[ -x "$exe" ] || { echo "build lantern-lammps first: cmake --build $build --target lantern_lammps"; exit 1; }
[ "$images" -ge 2 ] || { echo "IMAGES must be >= 2 (the set-up step is not timed by LAMMPS)"; exit 1; }
work=$(mktemp -d /tmp/lantern_lammps_bench.XXXXXX)
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
cat > "$work/bench.yaml" <<YAML
# Lantern's side: one PNG per callback, spheres of diameter 1 (LAMMPS: adiam 1.0).
lammps: {fix: viz}
scenes:
  - name: lj
    width: $size
    height: $size
    radius: 0.5
    samples: ${SAMPLES:-1}
    output:
      pattern: "$work/lantern_{step:06d}.png"
      asynchronous: ${ASYNC:-false}
$([ "${SSAO:-no}" = yes ] && echo "    ambient_occlusion: {method: screen}")
stats: "$work/stats.jsonl"
YAML
ssao=$([ "${SSAO:-no}" = yes ] && echo " ssao yes 4567 0.6" || true)
sed -e "/^run/i dump img all image $every $work/lammps_*.png type type size $size $size adiam 1.0$ssao" \
  -e "${NAPPLY:+s/^\(fix *viz .*pf\/callback *[^ ]*\) .*/\1 $NAPPLY/}" \
  "$root/examples/lammps/in.lj" > "$work/in.bench"
grep -q "^fix *viz .*pf/callback .* ${NAPPLY:-1000000000}\$" "$work/in.bench"
mpiflags=(--oversubscribe)
[ "$(id -u)" = 0 ] && mpiflags+=(--allow-run-as-root)
steps=$(( (images - 1) * every ))
atoms=$((4 * cells * cells * cells))
echo "LJ melt, $atoms atoms, ${size}x${size}, $images images every $every steps, $ranks MPI ranks, ssao ${SSAO:-no}, Lantern samples ${SAMPLES:-1}, napply ${NAPPLY:-1000000000}"
OMP_NUM_THREADS=1 mpiexec "${mpiflags[@]}" -n "$ranks" "$exe" -in "$work/in.bench" \
  -lantern "$work/bench.yaml" -log none -var cells "$cells" -var every "$every" \
  -var steps "$steps" > "$work/out.txt" 2> "$work/err.txt"
cat "$work/err.txt"
grep -E '^(Loop time|Output|Modify)' "$work/out.txt"
ls "$work"/lammps_*.png "$work"/lantern_*.png > /dev/null
# LAMMPS: "Output  | min | avg | max | %varavg | %total": the slowest rank's seconds.
lammps=$(awk -v n="$((images - 1))" '$1 == "Output" { printf "%.3f", $7 / n }' "$work/out.txt")
read -r lantern lantern_med < <(/usr/bin/python3 - "$work/stats.jsonl" <<'PY'
import json, statistics, sys
ms = [json.loads(l)["ms"]["total"] / 1000 for l in open(sys.argv[1])]
print(f"{statistics.mean(ms[1:]):.3f} {statistics.median(ms):.3f}")
PY
)
ratio=$(awk -v a="$lammps" -v b="$lantern" 'BEGIN { printf "%.1f", a / b }')
ratio_med=$(awk -v a="$lammps" -v b="$lantern_med" 'BEGIN { printf "%.1f", a / b }')
printf '\n| atoms | ranks | image | images | LAMMPS dump image s/image | Lantern s/image (mean after the first / median) | ratio |\n'
printf '|---|---|---|---|---|---|---|\n'
printf '| %d | %d | %dx%d | %d | %s | %s / %s | %sx / %sx |\n' "$atoms" "$ranks" "$size" "$size" \
  "$images" "$lammps" "$lantern" "$lantern_med" "$ratio" "$ratio_med"
