#!/bin/bash
# tests/dump end-to-end checks of lantern-render, run by CTest.
#   cli_test.sh MODE "MPIEXEC..." RANKS HELPER TOOL SRC_DIR WORK_DIR
# MODE png:  the C API helper renders particles and writes them as a LAMMPS text dump;
#            lantern-render renders that dump; the PNGs must be byte-identical. Then the dump is
#            converted to H5MD (float64) and rendered again: identical too.
# MODE orbit: the C API helper renders with a camera on an orbit (the step turns it);
#            lantern-render renders the dump with the same configuration (the step is the dump's
#            timestep): byte-identical PNGs. Against the still camera: the same at step 0, turned
#            at step 10.
# MODE h5py: lantern-render converts the dump to H5MD (float32); h5py_check.py reads it back.
# MODE split: lantern-render renders the dump with --split rows and with --split space (the
#            default): every image byte-identical, and the first scene equal to the C API's.
# MODE varying: the particle count changes (3000, 2400, 3200): the C API helper renders and dumps
#            H5MD in situ; lantern-render renders that H5MD and the LAMMPS text dump; all three
#            sets of PNGs must be byte-identical, and h5py reads the H5MD back (counts, fills).
# MODE movie: as varying, then lantern-render writes a movie from the H5MD and from the LAMMPS
#            text dump; ffprobe counts one frame per dumped step in each.
set -euo pipefail
mode=$1 mpiexec=$2 ranks=$3 helper=$4 tool=$5 src=$6 work=$7
run() { $mpiexec -n "$ranks" "$@"; }
rm -rf "$work" && mkdir -p "$work/api" "$work/tool" "$work/h5"
if [ "$mode" = varying ] || [ "$mode" = movie ]; then
  cd "$work/api" && run "$helper" "$src/varying_config.yaml" ../particles.lammpstrj varying
elif [ "$mode" = orbit ]; then
  cd "$work/api" && run "$helper" "$src/orbit_config.yaml" ../particles.lammpstrj
else
  cd "$work/api" && run "$helper" "$src/image_config.yaml" ../particles.lammpstrj
fi
case $mode in
varying)
  cd "$work/tool" && run "$tool" "$src/image_config.yaml" ../particles.lammpstrj
  cd "$work/h5" && run "$tool" "$src/image_config.yaml" ../api/insitu.h5
  cd "$work"
  n=0
  for f in api/*.png; do
    cmp "$f" "tool/$(basename "$f")"
    cmp "$f" "h5/$(basename "$f")"
    n=$((n + 1))
  done
  [ "$n" -eq 3 ] || { echo "expected 3 images, found $n"; exit 1; }
  echo "identical: $n images with changing counts (C API, LAMMPS dump, H5MD) at $ranks rank(s)"
  /usr/bin/python3 "$src/h5py_check.py" api/insitu.h5 particles.lammpstrj \
    --expect-counts 3000,2400,3200
  ;;
png)
  cd "$work/tool" && run "$tool" "$src/image_config.yaml" ../particles.lammpstrj
  cd "$work/h5"
  sed 's/float32/float64/' "$src/convert_config.yaml" > convert64.yaml
  run "$tool" convert64.yaml ../particles.lammpstrj
  run "$tool" "$src/image_config.yaml" converted.h5 --steps 0:10
  cd "$work"
  n=0
  for f in api/*.png; do
    cmp "$f" "tool/$(basename "$f")"
    cmp "$f" "h5/$(basename "$f")"
    n=$((n + 1))
  done
  [ "$n" -eq 2 ] || { echo "expected 2 images, found $n"; exit 1; }
  echo "identical: $n images (C API, LAMMPS dump, H5MD) at $ranks rank(s)"
  ;;
split)
  cd "$work/tool" && run "$tool" "$src/split_config.yaml" ../particles.lammpstrj --split rows
  cd "$work/h5" && run "$tool" "$src/split_config.yaml" ../particles.lammpstrj 2> split.log
  cat split.log
  if [ "$ranks" -gt 1 ]; then grep -q "spatial split" split.log; fi
  cd "$work"
  n=0
  for f in tool/*.png; do
    cmp "$f" "h5/$(basename "$f")"
    n=$((n + 1))
  done
  for f in api/*.png; do cmp "$f" "h5/$(basename "$f")"; done
  [ "$n" -eq 6 ] || { echo "expected 6 images, found $n"; exit 1; }
  echo "identical: $n images split by rows and by space at $ranks rank(s)"
  ;;
movie)
  cd "$work/h5" && run "$tool" "$src/movie_config.yaml" ../api/insitu.h5
  cd "$work/tool" && run "$tool" "$src/movie_config.yaml" ../particles.lammpstrj
  cd "$work"
  for movie in h5/cmp.mkv tool/cmp.mkv; do
    frames=$(ffprobe -v error -count_frames -select_streams v:0 \
      -show_entries stream=nb_read_frames,codec_name -of csv=p=0 "$movie")
    [ "$frames" = "ffv1,3" ] || { echo "$movie: expected ffv1,3 (codec, frames), got $frames"; exit 1; }
  done
  echo "movies: 3 frames each from the H5MD and the LAMMPS dump at $ranks rank(s)"
  ;;
orbit)
  cd "$work/tool" && run "$tool" "$src/orbit_config.yaml" ../particles.lammpstrj
  cd "$work/h5" && run "$tool" "$src/image_config.yaml" ../particles.lammpstrj
  cd "$work"
  n=0
  for f in api/*.png; do
    cmp "$f" "tool/$(basename "$f")"
    n=$((n + 1))
  done
  [ "$n" -eq 2 ] || { echo "expected 2 images, found $n"; exit 1; }
  cmp api/cmp_000000.png h5/cmp_000000.png
  if cmp -s api/cmp_000010.png h5/cmp_000010.png; then
    echo "step 10: the orbiting camera rendered the still camera's image"
    exit 1
  fi
  echo "orbit: $n identical images (C API, LAMMPS dump) at $ranks rank(s); step 10 turned"
  ;;
h5py)
  cd "$work/h5" && run "$tool" "$src/convert_config.yaml" ../particles.lammpstrj
  /usr/bin/python3 "$src/h5py_check.py" converted.h5 ../particles.lammpstrj
  ;;
esac
