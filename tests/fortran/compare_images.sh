#!/usr/bin/env bash
# Runs the Fortran example on RANKS ranks and the C reference on one, each in its own folder
# with the same configuration, and requires the two images to be the same bytes.
# Usage: compare_images.sh WORK_DIR CONFIG RANKS MPIEXEC... -- LATTICE_MD LATTICE_REFERENCE
set -euo pipefail
work=$1 config=$2 ranks=$3
shift 3
mpiexec=()
while [ "$1" != "--" ]; do mpiexec+=("$1"); shift; done
example=$2 reference=$3
rm -rf "$work" && mkdir -p "$work/fortran" "$work/c"
(cd "$work/fortran" && "${mpiexec[@]}" -n "$ranks" "$example" "$config")
(cd "$work/c" && "$reference" "$config")
cmp "$work/fortran/lattice_000004.png" "$work/c/lattice_000004.png"
echo "Fortran on $ranks ranks and C on 1: the same image ($(stat -c %s "$work/c/lattice_000004.png") bytes)"
