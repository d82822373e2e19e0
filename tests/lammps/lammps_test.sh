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
# MODE bonds: bonded systems drawn with their bonds by lantern-lammps at 1 and 3 ranks: bead-spring
#   chains across periodic faces (LAMMPS's bond list borrowed; newton_bond on and off) and
#   Debian's peptide example (SHAKE turns bonds off: gathered from the atoms' bond tables). The
#   first image is byte-identical at 1 and 3 ranks (LAMMPS's own trajectory differs in the last
#   bits between rank counts after that), every half-bond is drawn once (the stats count two per
#   bond, summed over ranks), and the image without bonds differs.
# MODE h5bonds: the chains' bonds written by lantern-lammps into Lantern's H5MD dump (its
#   connectivity; h5py checks it against the data file) and drawn by lantern-render from that
#   file alone, byte-identical to lantern-lammps.
# MODE bond_scalars: half-bonds colored by their atoms' scalar (vx, a compute, a variable), ghosts
#   included: identical at 1 and 3 ranks and to lantern-render of Lantern's H5MD dump.
# MODE triclinic: bonded chains in a triclinic box, with the box overlay and an H5MD dump: identical
#   at 1 and 3 ranks, to lantern-render of LAMMPS's dump and of the H5MD dump.
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
# chain_data [tilted]: 6 chains of 10 beads 0.97 apart, 4 across the x faces of the 10^3 box.
# tilted: a triclinic box (xy 2, xz 1, yz -1.5); the chains run along y and z and cross those
# faces, written in the box's own coordinates (sheared from the unit cell's, so bonds stay short).
chain_data() {
  awk -v tilted="${1:-}" 'BEGIN {
    n = 6; m = 10; L = 10; pi = 3.14159265358979; xy = 2; xz = 1; yz = -1.5
    printf "LAMMPS data file: bead-spring chains\n\n%d atoms\n%d bonds\n3 atom types\n2 bond types\n\n", n*m, n*(m-1)
    printf "0 %d xlo xhi\n0 %d ylo yhi\n0 %d zlo zhi\n", L, L, L
    if (tilted) printf "%g %g %g xy xz yz\n", xy, xz, yz
    printf "\nAtoms # bond\n\n"
    for (c = 0; c < n; c++) for (k = 0; k < m; k++) {
      x = 1.5 * c + 0.93 * k; y = 1 + 1.6 * c + ((k % 2) ? 0.15 : -0.15)
      z = 1 + 1.5 * c + 0.5 * sin(k * pi / 5)
      if (tilted) { u = x; x = y; y = u; z = 1 + 1.2 * c + 0.45 * k }
      x -= L * int(x / L); y -= L * int(y / L); z -= L * int(z / L)
      if (tilted) { x += (xy * y + xz * z) / L; y += yz * z / L }
      printf "%d %d %d %.10f %.10f %.10f\n", c*m + k + 1, c + 1, c % 3 + 1, x, y, z
    }
    printf "\nBonds\n\n"
    for (c = 0; c < n; c++) for (k = 0; k < m - 1; k++)
      printf "%d %d %d %d\n", c*(m-1) + k + 1, k % 2 + 1, c*m + k + 1, c*m + k + 2
  }' > chain.data
}
# case NAME RANKS SCRIPT YAML [LAMMPS ARGS]: lantern-lammps in folder NAME
case_run() {
  local name=$1 n=$2 in=$3 yaml=$4
  shift 4
  mkdir -p "$name" && cp chain.data "$name/" 2>/dev/null
  (cd "$name" && timeout 300 $mpiexec -n "$n" "$ll" -in "../$in" -lantern "$yaml" -log none \
     "$@" 2> err.txt > /dev/null; code=$?; cat err.txt; exit $code) || exit 1
}
# halves NAME BONDS: the first stats line counts 2 * BONDS half-bonds
halves() {
  grep -q "\"halves\":$((2 * $2))[,}]" <(head -1 "$1/stats.jsonl") ||
    { echo "$1: expected $((2 * $2)) half-bonds in: $(head -1 "$1/stats.jsonl")"; exit 1; }
}
same() {
  cmp "$1/mol_000000.png" "$2/mol_000000.png" || { echo "$1 and $2 differ"; exit 1; }
}
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
bonds)
  chain_data
  grep -v '^#' "$src/bonds.yaml" | sed '/bonds:/d' > nobonds.yaml
  for newton in on off; do
    sed "s/@NEWTON@/$newton/" "$src/in.chain" > "in.chain_$newton"
    for n in 1 3; do
      case_run "chain_${newton}_$n" $n "in.chain_$newton" "$src/bonds.yaml" -var steps 10
      halves "chain_${newton}_$n" 54
      grep -q "LAMMPS's own bond list, borrowed" "chain_${newton}_$n/err.txt" ||
        { echo "chain: the bond list was not borrowed"; exit 1; }
    done
    same "chain_${newton}_1" "chain_${newton}_3"
  done
  mkdir render && (cd render && timeout 300 $mpiexec -n 2 "$lr" "$src/bonds.yaml" \
    ../chain_on_3/positions.lammpstrj --bonds ../chain.data > /dev/null) || exit 1
  # The same with the bonds from LAMMPS's `dump local` of compute property/local.
  mkdir render_local && (cd render_local && timeout 300 $mpiexec -n 2 "$lr" "$src/bonds.yaml" \
    ../chain_on_3/positions.lammpstrj --bonds ../chain_on_3/bonds.local > /dev/null) || exit 1
  # Each rank's rows of the file (--split rows) instead of its run of the z-order curve (default).
  mkdir render_rows && (cd render_rows && timeout 300 $mpiexec -n 3 "$lr" "$src/bonds.yaml" \
    ../chain_on_3/positions.lammpstrj --bonds ../chain.data --split rows > /dev/null) || exit 1
  for s in 000000 000010; do
    for r in render render_local render_rows; do
      cmp "chain_on_3/mol_$s.png" "$r/mol_$s.png" ||
        { echo "$r: lantern-render of the dump differs from lantern-lammps at step $s"; exit 1; }
    done
  done
  case_run chain_nobonds 1 in.chain_on ../nobonds.yaml -var steps 10
  ! cmp -s chain_on_1/mol_000000.png chain_nobonds/mol_000000.png ||
    { echo "the bonds drew nothing"; exit 1; }
  # The peptide: LAMMPS's own positions differ in the last bits between 1 and 3 ranks from the
  # set-up on (SHAKE corrects the coordinates), so each run is compared with lantern-render of
  # its own dump instead, at 2 ranks, at step 10. (At the set-up step the image differs from the
  # dump's in one pixel by one level: there LAMMPS's ghost copies do not yet carry SHAKE's
  # correction of their owners, which the dump shows.)
  peptide=/usr/share/doc/lammps-examples/examples/peptide
  cp "$peptide/data.peptide" . && sed -e 's/^run.*/run 10/' \
    -e '/^group/a fix viz all external pf/callback 10 1' \
    -e '/^group/a dump d all custom 10 positions.lammpstrj id type x y z' \
    -e '/^group/a dump_modify d format float %.17g' "$peptide/in.peptide" > in.peptide
  for n in 1 3; do
    mkdir -p "peptide_$n" "peptide_render_$n" && cp data.peptide "peptide_$n/"
    case_run "peptide_$n" $n in.peptide "$src/bonds.yaml"
    halves "peptide_$n" 1365
    grep -q "gathered from the atoms' bond tables" "peptide_$n/err.txt" ||
      { echo "peptide: SHAKE's bonds need the gathered list"; exit 1; }
    (cd "peptide_render_$n" && timeout 300 $mpiexec -n 2 "$lr" "$src/bonds.yaml" \
      "../peptide_$n/positions.lammpstrj" --bonds ../data.peptide > /dev/null) || exit 1
    cmp "peptide_$n/mol_000010.png" "peptide_render_$n/mol_000010.png" ||
      { echo "peptide at $n ranks: lantern-render of the dump differs at step 10"; exit 1; }
  done
  echo "bonds: chains (newton_bond on, off): first image identical at 1 and 3 ranks; chains and peptide (1, 3 ranks): every half-bond drawn once, images identical to lantern-render of LAMMPS's dumps"
  ;;
h5bonds)
  # Lantern's H5MD dump of the chains (connectivity by atom id, newton_bond on and off, 1 and 3
  # ranks) drawn by lantern-render from the dump alone: every bond once (54), and the images of
  # lantern-lammps (newton_bond on) or of the data file's bonds (off), bit for bit.
  chain_data
  { grep -v '^#' "$src/bonds.yaml"; printf 'dump:\n  file: mol.h5\n  schedule: {every: 10}\n'; } \
    > dump.yaml
  for newton in on off; do
    sed "s/@NEWTON@/$newton/" "$src/in.chain" > "in.chain_$newton"
    for n in 1 3; do
      case_run "h5_${newton}_$n" $n "in.chain_$newton" ../dump.yaml -var steps 10
      # h5py, a reader of its own: the reference names /particles/all, and each frame's pairs are
      # the data file's bonds, each once.
      /usr/bin/python3 - "h5_${newton}_$n/mol.h5" chain.data <<'PY' || exit 1
import sys, h5py
f = h5py.File(sys.argv[1], "r")
bonds = f["connectivity/all_bonds"]
assert f[bonds.attrs["particles_group"]].name == "/particles/all", "particles_group"
lines = open(sys.argv[2]).read().split("Bonds")[1].split()
want = {tuple(sorted(map(int, lines[i + 2:i + 4]))) for i in range(0, len(lines), 4)}
for k, frame in enumerate(bonds["value"]):
    pairs = [tuple(sorted(p)) for p in frame.tolist() if p != [-1, -1]]
    assert len(pairs) == len(set(pairs)) and set(pairs) == want, f"frame {k}: {len(pairs)} pairs"
assert list(bonds["step"]) == [0, 10], list(bonds["step"])
PY
      for split in space rows; do
        out="render_${newton}_${n}_$split"
        mkdir "$out" && (cd "$out" && timeout 300 $mpiexec -n 2 "$lr" "$src/bonds.yaml" \
          "../h5_${newton}_$n/mol.h5" --split $split > /dev/null) || exit 1
        # With newton_bond off LAMMPS draws a bond across a periodic face as two halves at
        # their own atoms (listed by both), where a bond list by id draws it whole at its first
        # atom (as newton_bond on): there the dump's bonds must give the data file's image.
        ref="h5_${newton}_$n"
        if [ $newton = off ]; then
          ref="data_${newton}_${n}_$split"
          mkdir "$ref" && (cd "$ref" && timeout 300 $mpiexec -n 2 "$lr" "$src/bonds.yaml" \
            "../h5_${newton}_$n/mol.h5" --split $split --bonds ../chain.data > /dev/null) || exit 1
        fi
        for s in 000000 000010; do
          cmp "$ref/mol_$s.png" "$out/mol_$s.png" ||
            { echo "$out: lantern-render of the H5MD dump differs from $ref at step $s"; exit 1; }
        done
        halves "$out" 54
      done
    done
  done
  echo "h5bonds: chains (newton_bond on, off; 1, 3 ranks): lantern-render of the H5MD dump (split by space and rows, 2 ranks) draws the 54 bonds and gives lantern-lammps's images (on) and the data file's (off)"
  ;;
bond_scalars)
  # Half-bonds colored by their atom's scalar (color.by: scalar, bonds by_atom): the ghosts' values,
  # which LAMMPS does not communicate for vx, a compute or a variable, are their owners'. The
  # chains cross the periodic faces, so half-bonds at ghosts are drawn at 1 rank too. The first
  # image is byte-identical at 1 and 3 ranks, and lantern-render of Lantern's H5MD dump (owned
  # atoms' scalars only; it gives each bond end its atom's value itself) draws the same images.
  chain_data
  for scalar in vx c_ke v_height; do
    { grep -v '^#' "$src/bonds.yaml" | sed 's/bonds: {radius: 0.15}/bonds: {radius: 0.15}\n    color: {by: scalar}/'
      printf 'dump:\n  file: mol.h5\n  schedule: {every: 10}\n'
      printf 'lammps: {scalar: %s}\n' "$scalar"; } > "scalar_$scalar.yaml"
    grep -q 'by: scalar' "scalar_$scalar.yaml" || { echo "the YAML edit failed"; exit 1; }
    sed -e "s/@NEWTON@/on/" -e '/^run/i compute ke all ke/atom' \
      -e '/^run/i variable height atom z*z+0.5*y' "$src/in.chain" > in.scalar
    for n in 1 3; do
      case_run "s_${scalar}_$n" $n in.scalar "../scalar_$scalar.yaml" -var steps 10
      halves "s_${scalar}_$n" 54
      mkdir "r_${scalar}_$n" && (cd "r_${scalar}_$n" && timeout 300 $mpiexec -n 2 "$lr" \
        "../scalar_$scalar.yaml" "../s_${scalar}_$n/mol.h5" > /dev/null) || exit 1
      for s in 000000 000010; do
        cmp "s_${scalar}_$n/mol_$s.png" "r_${scalar}_$n/mol_$s.png" ||
          { echo "$scalar at $n ranks: lantern-render of the dump differs at step $s"; exit 1; }
      done
    done
    same "s_${scalar}_1" "s_${scalar}_3"
    # Each scalar colours the chains its own way.
    ! cmp -s "s_${scalar}_1/mol_000000.png" "s_vx_1/mol_000000.png" || [ "$scalar" = vx ] ||
      { echo "$scalar and vx give the same image"; exit 1; }
  done
  echo "bond_scalars: vx, c_ke, v_height: half-bonds colored by their atoms' scalars, first image identical at 1 and 3 ranks, images identical to lantern-render of the H5MD dumps"
  ;;
triclinic)
  # A triclinic box: bonds across its tilted faces take LAMMPS's closest images, and the box
  # overlay draws the parallelepiped. Lantern's H5MD dump records the edges as the matrix of
  # LAMMPS's edge vectors (h5py checks it against LAMMPS's own box). The first image is
  # byte-identical at 1 and 3 ranks, and lantern-render draws the same images from LAMMPS's dump
  # (its triclinic bounds) with the data file's bonds, and from the H5MD dump alone.
  chain_data tilted
  { grep -v '^#' "$src/bonds.yaml"; echo "    box: {color: [0, 0, 0], width: 1}"
    printf 'dump:\n  file: mol.h5\n  schedule: {every: 10}\n'; } > tri.yaml
  sed -e "s/@NEWTON@/on/" -e '/^run/i thermo_style custom step xy xz yz lx ly lz' \
    -e '/^run/i thermo 10' "$src/in.chain" > in.tri
  for n in 1 3; do
    case_run "tri_$n" $n in.tri ../tri.yaml -var steps 10
    halves "tri_$n" 54
  done
  same tri_1 tri_3
  /usr/bin/python3 - tri_3/mol.h5 <<'PY' || exit 1
import sys, h5py, numpy as np
box = h5py.File(sys.argv[1], "r")["particles/all/box"]
edges = box["edges/value"][0]
assert edges.shape == (3, 3), edges.shape
want = np.array([[10, 0, 0], [2, 10, 0], [1, -1.5, 10]], dtype=float)
assert np.allclose(edges, want, rtol=0, atol=1e-12), edges
assert np.allclose(box["offset/value"][0], [0, 0, 0], atol=1e-12), box["offset/value"][0]
PY
  mkdir tri_render tri_render_h5 && (cd tri_render && timeout 300 $mpiexec -n 2 "$lr" ../tri.yaml \
    ../tri_3/positions.lammpstrj --bonds ../chain.data > /dev/null) || exit 1
  (cd tri_render_h5 && timeout 300 $mpiexec -n 2 "$lr" ../tri.yaml ../tri_3/mol.h5 > /dev/null) ||
    exit 1
  for s in 000000 000010; do
    for r in tri_render tri_render_h5; do
      cmp "tri_3/mol_$s.png" "$r/mol_$s.png" ||
        { echo "$r: lantern-render differs from lantern-lammps at step $s"; exit 1; }
    done
  done
  # The dump's box read as the orthogonal one of its bounds draws another image: the tilt is used.
  mkdir tri_ortho && sed -e 's/^ITEM: BOX BOUNDS xy xz yz/ITEM: BOX BOUNDS/' \
    -e '/^ITEM: BOX BOUNDS/,/^ITEM: ATOMS/s/^\([^ I]*\) \([^ ]*\) [^ ]*$/\1 \2/' \
    tri_3/positions.lammpstrj > tri_ortho/positions.lammpstrj
  grep -q "^ITEM: BOX BOUNDS pp" tri_ortho/positions.lammpstrj || { echo "sed failed"; exit 1; }
  (cd tri_ortho && timeout 300 $mpiexec -n 2 "$lr" ../tri.yaml positions.lammpstrj \
    --bonds ../chain.data > /dev/null) || exit 1
  ! cmp -s tri_3/mol_000000.png tri_ortho/mol_000000.png || { echo "the tilt changed nothing"; exit 1; }
  echo "triclinic: chains across tilted faces (1, 3 ranks): images identical, to lantern-render of LAMMPS's dump and of the H5MD dump (edges as a matrix)"
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
