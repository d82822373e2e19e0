#!/bin/bash
# tests/lammps: lantern-lammps end to end, run by CTest.
#   lammps_test.sh MODE "MPIEXEC..." RANKS LANTERN_LAMMPS LANTERN_RENDER LMP SRC_DIR WORK_DIR [...]
# MODE image GROUP: lantern-lammps renders in.small (fix external on GROUP) at steps 0, 10, 20
#   while LAMMPS dumps the GROUP's atoms at the same steps (full precision); lantern-render
#   renders the dump through the C API: the PNGs must be byte-identical.
# MODE runs: two runs and a minimize: images at every callback step, each step once, and the
#   final positions byte-identical to LAMMPS's own `lmp` on the script without the fix line
#   (fix external leaves the forces alone).
# MODE scalars: lammps.scalar as a compute, an array column, an atom-style variable, a property.
# MODE example: examples/lammps/in.lj at CI size with tests/dump/lammps_small.yaml.
# MODE quit: `quit N` (a number, a variable, inside an include) after a run: lantern-lammps exits
#   with N as lmp does, after rendering the run's steps.
# MODE error NAME "EXPECTED" "YAML LINES" "SED EXPRESSION" [LANTERN-LAMMPS ARGS]: the script
#   edited by the sed expression, the configuration extended by the YAML lines: lantern-lammps
#   must exit non-zero (not killed, not hung) with EXPECTED in its stderr.
set -uo pipefail
mode=$1 mpiexec=$2 ranks=$3 ll=$4 lr=$5 lmp=$6 src=$7 work=$8
shift 8
run() { timeout 300 $mpiexec -n "$ranks" "$@"; }
script() {  # script GROUP > file: in.small with the fix's group written in
  sed "s/@GROUP@/$1/g" "$src/in.small"
}
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
case $mode in
image)
  group=$1
  mkdir ll lr
  script "$group" > in.case
  (cd ll && run "$ll" -in ../in.case -lantern "$src/lj.yaml" -log none -var steps 20) || exit 1
  (cd lr && run "$lr" "$src/lj.yaml" ../ll/positions.lammpstrj) || exit 1
  n=0
  for f in ll/lj_*.png; do
    cmp "$f" "lr/$(basename "$f")" || exit 1
    n=$((n + 1))
  done
  [ "$n" -eq 3 ] || { echo "expected 3 images, found $n"; exit 1; }
  echo "identical: $n images (lantern-lammps, group $group; lantern-render of LAMMPS's dump) at $ranks rank(s)"
  ;;
runs)
  mkdir ll plain
  script all | sed -e 's/pf\/callback 10 1/pf\/callback 5 1/' -e '/^dump/d' -e '/^run/d' > in.case
  cat >> in.case <<'LMP'
run             10
run             10
minimize        1.0e-6 1.0e-8 30 300
write_dump      all custom final.txt id x y z vx vy vz modify sort id format float %.17g
LMP
  grep -v 'external' in.case > in.plain
  (cd ll && run "$ll" -in ../in.case -lantern "$src/lj.yaml" -log none 2> err.txt; code=$?
   cat err.txt; exit $code) || exit 1
  (cd plain && run "$lmp" -in ../in.plain -log none > /dev/null) || exit 1
  cmp ll/final.txt plain/final.txt || { echo "fix external changed the trajectory"; exit 1; }
  for s in 0 5 10 15 20; do
    [ -f "ll/lj_$(printf %06d $s).png" ] || { echo "no image at step $s"; exit 1; }
  done
  after=$(ls ll/lj_*.png | sed -E 's/.*lj_0*([0-9]+)\.png/\1/' | awk '$1 > 20' | wc -l)
  [ "$after" -ge 1 ] || { echo "no image during minimize"; exit 1; }
  total=$(ls ll/lj_*.png | wc -l)
  grep -q "lantern-lammps: $total rendered steps" ll/err.txt ||
    { echo "expected $total rendered steps (each step once)"; exit 1; }
  echo "runs: $total images (5 in two runs, $after in minimize), trajectory identical to lmp"
  ;;
scalars)  # every kind of scalar name colors an image: compute, array column, variable, property
  script all | sed -e '/^run/i compute ke all ke/atom' \
    -e '/^run/i compute p all property/atom vx vy vz' \
    -e '/^run/i variable speed atom sqrt(vx*vx+vy*vy+vz*vz)' > in.case
  for name in c_ke 'c_p[2]' v_speed vx; do
    mkdir -p "s_$name" && cd "s_$name" || exit 1
    { cat "$src/lj.yaml" | sed 's/radius: 0.5/radius: 0.5\n    color: {by: scalar}/'
      echo "lammps: {scalar: '$name'}"; } > scalar.yaml
    run "$ll" -in ../in.case -lantern scalar.yaml -log none -var steps 20 > /dev/null || exit 1
    [ "$(ls lj_*.png | wc -l)" -eq 3 ] || { echo "$name: expected 3 images"; exit 1; }
    cd ..
  done
  # Colored by different quantities, the images differ.
  ! cmp -s "s_c_ke/lj_000010.png" "s_vx/lj_000010.png" || { echo "c_ke and vx gave one image"; exit 1; }
  echo "scalars: c_ke, c_p[2], v_speed, vx each colored 3 images"
  ;;
example)  # examples/lammps/in.lj at CI size (256 atoms), images and an H5MD dump
  run "$ll" -in "$src/../../examples/lammps/in.lj" -lantern "$src/../dump/lammps_small.yaml" \
    -log none -var cells 4 -var every 10 -var steps 20 || exit 1
  for s in 0 10 20; do
    [ -f "lj_$(printf %06d $s).png" ] || { echo "no image at step $s"; exit 1; }
  done
  [ -s lj.h5 ] || { echo "no H5MD dump"; exit 1; }
  echo "example: 3 images and an H5MD dump"
  ;;
example_movie)  # the same example as the README's LAMMPS movie (config/lammps_movie.yaml)
  run "$ll" -in "$src/../../examples/lammps/in.lj" -lantern "$src/../../config/lammps_movie.yaml" \
    -log none -var cells 4 -var every 10 -var steps 60 || exit 1
  # ffprobe, an independent reader, decodes and counts the frames: steps 0, 10, ..., 60.
  frames=$(ffprobe -v error -count_frames -select_streams v:0 \
    -show_entries stream=nb_read_frames,width,height -of csv=p=0 images/melt.mp4)
  [ "$frames" = "960,720,7" ] || { echo "images/melt.mp4: '$frames', expected 960,720,7"; exit 1; }
  echo "example_movie: images/melt.mp4 holds 7 frames of 960x720"
  ;;
quit)  # quit N: lantern-lammps exits with LAMMPS's status N (literal, variable, in an include)
  script all > in.base
  printf 'variable code equal 4\nquit ${code}\nrun 10\n' > quit.inc
  for case in "quit 3:3" 'quit ${code}:4' "include quit.inc:4" "quit:0"; do
    { cat in.base; echo "variable code equal 4"; echo "${case%:*}"; echo "run 10"; } > in.case
    expect=${case##*:}
    rm -f lj_*.png
    grep -v external in.case > in.plain  # lmp itself cannot run a pf/callback fix
    run "$lmp" -in in.plain -log none -var steps 0 > /dev/null 2>&1
    lmp_code=$?
    run "$ll" -in in.case -lantern "$src/lj.yaml" -log none -var steps 0 > /dev/null 2> err.txt
    code=$?
    cat err.txt
    [ "$lmp_code" -eq "$expect" ] || { echo "FAIL: lmp exited $lmp_code on '${case%:*}'"; exit 1; }
    [ "$code" -eq "$expect" ] ||
      { echo "FAIL: lantern-lammps exited $code on '${case%:*}', lmp $lmp_code"; exit 1; }
    # The run before the quit rendered its steps; the one after it did not run.
    [ "$(ls lj_*.png | wc -l)" -eq 1 ] || { echo "FAIL: expected the image of step 0"; exit 1; }
    echo "ok: '${case%:*}' exits $code, as lmp"
  done
  ;;
error)
  name=$1 expected=$2 yaml=$3 edit=$4  # '-': no YAML lines, no edit (CTest drops empty arguments)
  shift 4
  [ "$yaml" = - ] && yaml=
  [ "$edit" = - ] && edit=
  if [ -n "$edit" ]; then script all | sed -e "$edit"; else script all; fi > in.case
  { cat "$src/lj.yaml"; printf '%b\n' "$yaml"; } > case.yaml
  err=$(run "$ll" -in in.case -lantern case.yaml -log none -var steps 20 "$@" 2>&1 > /dev/null)
  code=$?
  echo "$err"
  if [ "$code" -eq 0 ]; then echo "FAIL: exit code 0"; exit 1; fi
  if [ "$code" -eq 124 ]; then echo "FAIL: hung (timeout)"; exit 1; fi
  if [ "$code" -gt 128 ]; then echo "FAIL: killed (exit $code)"; exit 1; fi
  if [[ "$err" != *"$expected"* ]]; then echo "FAIL: expected '$expected' in stderr"; exit 1; fi
  echo "ok ($name): exit $code with '$expected'"
  ;;
*)
  echo "unknown mode $mode"; exit 2 ;;
esac
