#!/bin/bash
# tests/dump: a LAMMPS run that evaporates atoms reaches Lantern two ways, and both H5MD files
# must hold, frame by frame, exactly LAMMPS's atoms:
#   in situ:  lantern-lammps hands LAMMPS's own arrays to Lantern every 10 steps (images + evap_insitu.h5, count changing as atoms evaporate);
#   offline:  lantern-render converts LAMMPS's text dump of the same steps to H5MD and renders it.
# h5py_check.py compares each file's per-frame counts with LAMMPS's own `$(atoms)` at those steps
# and its particles (by id) with the text dump.
#   evaporate_test.sh "MPIEXEC..." RANKS DRIVER TOOL SRC_DIR WORK_DIR
set -euo pipefail
mpiexec=$1 ranks=$2 driver=$3 tool=$4 src=$5 work=$6
run() { $mpiexec -n "$ranks" "$@"; }
rm -rf "$work" && mkdir -p "$work" && cd "$work"
run "$driver" -in "$src/in.evaporate" -lantern "$src/evaporate.yaml" -log none
ls evap_000040.png >/dev/null
run "$tool" "$src/convert_config.yaml" evap.lammpstrj
check() {
  /usr/bin/python3 "$src/h5py_check.py" "$1" evap.lammpstrj --atol 1e-8 \
    --lammps-counts lammps_counts.txt --expect-loss
}
check evap_insitu.h5
check converted.h5
