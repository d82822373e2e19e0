#!/bin/bash
# LAMMPS `dump image ... bond atom` vs Lantern with bonds on the same bonded network, in one run,
# same image size and cadence.
#
#   tests/bench/lammps_dump_image_bonds.sh [BUILD_DIR] [CELLS] [SIZE] [IMAGES] [EVERY] [RANKS]
#   defaults: build, 80 (80^3 = 512,000 atoms, 1,536,000 bonds), 1024, 4, 5, 2
#
# The system: a simple-cubic lattice of spacing 1 whose nearest neighbours are bonded by LAMMPS's
# own `create_bonds many` (a network of 3 bonds per atom, harmonic, periodic in x, y, z: the bonds
# across the faces join atoms on opposite sides), at a low temperature. lantern-lammps runs it
# with `fix viz all external pf/callback EVERY 1000000000` and one more line, `dump img all image
# EVERY ... bond atom 0.3 size SIZE SIZE adiam 0.5`: every EVERY steps LAMMPS draws its image dump
# and Lantern its image (spheres of radius 0.25, bonds of radius 0.15, colored by atom), in the
# same run. Seconds per image: LAMMPS's from its timing breakdown ("Output", slowest rank, images
# after the set-up step), Lantern's from its stats (ms.total after the first step, and the median
# of all). The target: Lantern >= 10x faster per image at >= 500 k bonded atoms on 2 ranks.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
cells=${2:-80} size=${3:-1024} images=${4:-4} every=${5:-5} ranks=${6:-2}
exe=$build/adaptor/lammps/lantern-lammps
[ -x "$exe" ] || { echo "build lantern-lammps first: cmake --build $build --target lantern_lammps"; exit 1; }
[ "$images" -ge 2 ] || { echo "IMAGES must be >= 2 (the set-up step is not timed by LAMMPS)"; exit 1; }
work=$(mktemp -d /tmp/lantern_lammps_bonds_bench.XXXXXX)
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
cat > "$work/bench.yaml" <<YAML
lammps: {fix: viz}
scenes:
  - name: network
    width: $size
    height: $size
    radius: 0.25
    bonds: {radius: 0.15, color: by_atom}
    output:
      pattern: "$work/lantern_{step:06d}.png"
stats: "$work/stats.jsonl"
YAML
steps=$(( (images - 1) * every ))
cat > "$work/in.bench" <<LMP
units           lj
atom_style      bond
lattice         sc 1.0
region          box block 0 $cells 0 $cells 0 $cells
create_box      2 box bond/types 1 extra/bond/per/atom 6 extra/special/per/atom 12
create_atoms    1 box
set             type 1 type/fraction 2 0.5 12345
mass            * 1.0
pair_style      lj/cut 1.12246
pair_coeff      * * 0.2 0.8
bond_style      harmonic
bond_coeff      1 50.0 1.0
special_bonds   lj 0.0 1.0 1.0
create_bonds    many all all 1 0.99 1.01
velocity        all create 0.05 87287 loop geom
fix             1 all nve
fix             viz all external pf/callback $every 1000000000
dump            img all image $every $work/lammps_*.png type type bond atom 0.3 size $size $size adiam 0.5
run             $steps
LMP
mpiflags=(--oversubscribe)
[ "$(id -u)" = 0 ] && mpiflags+=(--allow-run-as-root)
atoms=$((cells * cells * cells))
echo "bonded sc network, $atoms atoms, $((3 * atoms)) bonds, ${size}x${size}, $images images every $every steps, $ranks MPI ranks"
OMP_NUM_THREADS=1 mpiexec "${mpiflags[@]}" -n "$ranks" "$exe" -in "$work/in.bench" \
  -lantern "$work/bench.yaml" -log none > "$work/out.txt" 2> "$work/err.txt"
cat "$work/err.txt"
grep -E '^(Loop time|Output|Modify|Created)' "$work/out.txt" || true
ls "$work"/lammps_*.png "$work"/lantern_*.png > /dev/null
lammps=$(awk -v n="$((images - 1))" '$1 == "Output" { printf "%.3f", $7 / n }' "$work/out.txt")
read -r lantern lantern_med halves reused < <(/usr/bin/python3 - "$work/stats.jsonl" <<'PY'
import json, statistics, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
ms = [l["ms"]["total"] / 1000 for l in lines]
scene = lines[0]["scenes"][0] if "scenes" in lines[0] else lines[0]
# Steps whose half-bond grouping was refit rather than built, over steps x ranks.
reused = sum(s.get("bonds", {}).get("grouping_reused", 0)
             for l in lines for s in l.get("scenes", [l]))
print(f"{statistics.mean(ms[1:]):.3f} {statistics.median(ms):.3f} "
      f"{json.dumps(scene.get('bonds', {})).replace(' ', '')} {reused}")
PY
)
ratio=$(awk -v a="$lammps" -v b="$lantern" 'BEGIN { printf "%.1f", a / b }')
ratio_med=$(awk -v a="$lammps" -v b="$lantern_med" 'BEGIN { printf "%.1f", a / b }')
echo "Lantern's half-bonds (first step): $halves"
echo "Half-bond grouping kept from an earlier step (refit, not built): $reused of $((images * ranks)) rank-steps"
printf '\n| atoms | bonds | ranks | image | images | LAMMPS dump image bond atom s/image | Lantern s/image (mean after the first / median) | ratio |\n'
printf '|---|---|---|---|---|---|---|---|\n'
printf '| %d | %d | %d | %dx%d | %d | %s | %s / %s | %sx / %sx |\n' "$atoms" "$((3 * atoms))" \
  "$ranks" "$size" "$size" "$images" "$lammps" "$lantern" "$lantern_med" "$ratio" "$ratio_med"
