#!/usr/bin/env bash
# mini_md against LAMMPS on the LAMMPS bench/in.lj problem, side by side in one run.
#
#   in.lj: fcc at reduced density 0.8442, T 1.44, LJ cutoff 2.5 (unshifted), skin 0.3,
#   neighbour list rebuilt every 20 steps without displacement check, NVE, 100 steps.
#
# For each size (32k, 256k, 2M atoms) and rank count (1, 2) both codes run REPEATS times,
# alternating, and the median loop time of each is reported: LAMMPS's "Loop time" line and
# mini_md's PERF seconds= (the same span: the 100 steps, without setup).
#
# Usage: tests/bench/md_vs_lammps.sh [path/to/mini_md]
# Environment: REPEATS (default 3), CELLS (default "20 40 80"), RANKS (default "1 2"),
#              CSV (default md_vs_lammps.csv), MPIEXEC (default: mpiexec --oversubscribe
#              [--allow-run-as-root]).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
mini_md=${1:-}
if [[ -z "$mini_md" ]]; then
  for candidate in "$repo"/build*/mini_md/mini_md; do
    [[ -x "$candidate" ]] && mini_md=$candidate && break
  done
fi
[[ -x "${mini_md:-}" ]] || { echo "md_vs_lammps: build mini_md first or pass its path" >&2; exit 2; }

if ! command -v lmp >/dev/null 2>&1; then
  echo "md_vs_lammps: lmp not found; installing the Debian package lammps" >&2
  if [[ $(id -u) -eq 0 ]]; then apt-get install -y lammps >&2; else sudo apt-get install -y lammps >&2; fi
fi

REPEATS=${REPEATS:-3}
CELLS=${CELLS:-"20 40 80"}
RANKS=${RANKS:-"1 2"}
CSV=${CSV:-md_vs_lammps.csv}
if [[ -z "${MPIEXEC:-}" ]]; then
  MPIEXEC="mpiexec --oversubscribe"
  [[ $(id -u) -eq 0 ]] && MPIEXEC="$MPIEXEC --allow-run-as-root"
fi
export OMP_NUM_THREADS=1

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# bench/in.lj from the LAMMPS distribution, box scaled by x, y, z (20 fcc cells each).
cat > "$work/in.lj" <<'LJ'
variable x index 1
variable y index 1
variable z index 1
variable xx equal 20*$x
variable yy equal 20*$y
variable zz equal 20*$z
units lj
atom_style atomic
lattice fcc 0.8442
region box block 0 ${xx} 0 ${yy} 0 ${zz}
create_box 1 box
create_atoms 1 box
mass 1 1.0
velocity all create 1.44 87287 loop geom
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0 2.5
neighbor 0.3 bin
neigh_modify delay 0 every 20 check no
fix 1 all nve
run 100
LJ

median() { sort -g | awk '{a[NR]=$1} END {if (NR%2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2}'; }

run_lammps() {  # cells ranks -> loop seconds
  local scale=$(( $1 / 20 ))
  (cd "$work" && $MPIEXEC -n "$2" lmp -in in.lj -var x "$scale" -var y "$scale" -var z "$scale" \
      -screen none -echo none -log "$work/log.lammps" >/dev/null 2>&1)
  awk '/^Loop time of/ {print $4}' "$work/log.lammps"
}

run_mini_md() {  # cells ranks -> loop seconds
  $MPIEXEC -n "$2" "$mini_md" --cells "$1" --steps 100 --neigh-every 20 --neigh-check no \
      --thermo 0 | sed -n 's/^PERF .* seconds=\([0-9.]*\) .*/\1/p'
}

echo "mini_md: $mini_md"
echo "LAMMPS:  $(command -v lmp) ($(lmp -h 2>/dev/null | sed -n 's/^Large-scale[^-]*- //p' | head -1))"
echo "in.lj, 100 steps, median of $REPEATS alternating runs each; host: $(getconf _NPROCESSORS_ONLN) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%10s %6s %12s %14s %12s %14s %8s\n' atoms ranks lammps_s lammps_at_s mini_md_s mini_md_at_s ratio
echo "atoms,ranks,lammps_seconds,lammps_atom_steps_per_s,mini_md_seconds,mini_md_atom_steps_per_s,ratio" > "$CSV"
for cells in $CELLS; do
  (( cells % 20 == 0 )) || { echo "md_vs_lammps: CELLS entries must be multiples of 20" >&2; exit 2; }
  atoms=$(( 4 * cells * cells * cells ))
  for ranks in $RANKS; do
    : > "$work/l.txt"; : > "$work/m.txt"
    for ((r = 0; r < REPEATS; ++r)); do
      run_lammps "$cells" "$ranks" >> "$work/l.txt"
      run_mini_md "$cells" "$ranks" >> "$work/m.txt"
    done
    ls=$(median < "$work/l.txt"); ms=$(median < "$work/m.txt")
    read -r lr mr ratio < <(awk -v n="$atoms" -v l="$ls" -v m="$ms" \
        'BEGIN {printf "%.4e %.4e %.3f\n", n*100/l, n*100/m, l/m}')
    printf '%10d %6d %12.4f %14s %12.4f %14s %8s\n' "$atoms" "$ranks" "$ls" "$lr" "$ms" "$mr" "$ratio"
    echo "$atoms,$ranks,$ls,$lr,$ms,$mr,$ratio" >> "$CSV"
  done
done
echo "ratio = mini_md atom-steps/s / LAMMPS atom-steps/s (> 1: mini_md faster). CSV: $CSV"
