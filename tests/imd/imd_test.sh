#!/bin/bash
# tests/imd: lantern-imd end to end against the real simulations, over loopback, run by CTest.
#   imd_test.sh MODE "MPIEXEC..." RANKS LANTERN_IMD SRC_DIR WORK_DIR [TOOLS...]
# MODE lammps (TOOLS: lantern-lammps lantern-render): lantern-lammps runs in.imd, rendering in
#   situ at steps 0, 10, ... 40 and dumping them in float32, while its fix imd streams steps
#   10 ... 40 to lantern-imd on RANKS ranks; between the two runs the simulation pauses. lantern-
#   imd must wait through the pause, end cleanly when LAMMPS ends, and its images must be byte-
#   identical to lantern-render's of the float32 dump (what IMD carries: positions rounded to
#   float32) and to lantern-lammps's own (float64; float32 rounding moves no pixel of this scene),
#   its dump's positions bit-identical to lantern-lammps's float32 dump.
# MODE leave (TOOLS: lmp): three clients in turn on one LAMMPS run that waits for a client:
#   one leaves after --frames 2, one is stopped by SIGTERM, one sees the run end; every client
#   exits 0 with intact images, and LAMMPS carries on to the end each time. Between its two runs
#   LAMMPS waits until the second client is stopped, however slow that client is.
# MODE example (TOOLS: lmp): examples/imd/in.melt and viz.yaml at CI size.
# MODE hostile: a server that sends one good frame then a truncated one:
#   lantern-imd on RANKS ranks exits 1 naming the truncation, the first image intact, no hang.
# MODE gromacs (TOOLS: gmx): GROMACS's mdrun -imdport on an argon box: lantern-imd's
#   images equal python3 -m lantern.render's of GROMACS's own TRR at the same steps; the XTC and
#   the GRO render too.
set -uo pipefail
mode=$1 mpiexec=$2 ranks=$3 imd=$4 src=$5 work=$6
shift 6
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
python=${LANTERN_PYTHON:-python3}  # the interpreter with h5py (Debian's)
fail() { echo "FAIL: $*"; exit 1; }
free_port() { "$python" -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
# run_imd DIR RANKS ARGS...: lantern-imd in DIR (1 rank: without mpiexec), its exit code in DIR/rc.
run_imd() {
  local dir=$1 n=$2
  shift 2
  mkdir -p "$dir"
  if [ "$n" -eq 1 ]; then
    (cd "$dir" && timeout 120 "$imd" "$@" > out.txt 2>&1; echo $? > rc)
  else
    (cd "$dir" && timeout 120 $mpiexec -n "$n" "$imd" "$@" > out.txt 2>&1; echo $? > rc)
  fi
}
expect_rc() {  # expect_rc DIR CODE
  local rc
  rc=$(cat "$1/rc")
  [ "$rc" = "$2" ] || { cat "$1/out.txt"; fail "$1: lantern-imd exited $rc, expected $2"; }
}
expect_text() {  # expect_text FILE TEXT
  grep -qF -- "$2" "$1" || { cat "$1"; fail "$1 lacks '$2'"; }
}
valid_png() { iinfo "$1" > /dev/null 2>&1 || fail "$1 is not a readable image"; }

case $mode in
lammps)
  ll=$1 lr=$2
  port=$(free_port)
  run_imd imd "$ranks" "127.0.0.1:$port" -lantern "$src/lj.yaml" --every 10 \
    --types ../ll/types.lammpstrj &
  client=$!
  mkdir ll lr
  (cd ll && exec timeout 120 "$ll" -in "$src/in.imd" -lantern "$src/lj.yaml" -log none \
     -var port "$port" -var pause 1 -var steps 20 -var wait off > out.txt 2>&1) &
  simulation=$!
  wait "$client"
  # A failed client leaves LAMMPS waiting for the next one: stop it rather than wait.
  [ "$(cat imd/rc)" = 0 ] || kill "$simulation"
  expect_rc imd 0
  wait "$simulation" || { cat ll/out.txt; fail "lantern-lammps failed"; }
  cat imd/out.txt
  expect_text imd/out.txt "the simulation closed the connection"
  expect_text imd/out.txt "4 frames rendered (steps 10..40), 0 dropped"
  (cd lr && "$lr" "$src/lj.yaml" ../ll/atoms.h5 --steps 10:40 > out.txt 2>&1) ||
    { cat lr/out.txt; fail "lantern-render failed"; }
  for s in 10 20 30 40; do
    f=lj_$(printf %06d $s).png
    cmp imd/$f lr/$f || fail "step $s: lantern-imd's image differs from the float32 positions'"
    cmp imd/$f ll/$f || fail "step $s: lantern-imd's image differs from lantern-lammps's"
  done
  "$python" - ll/atoms.h5 imd/atoms.h5 <<'PY' || fail "the dumps' positions differ"
import sys
import h5py
import numpy as np
def frames(path):
    g = h5py.File(path, "r")["particles/all"]
    steps = list(g["position/step"][:])
    return {s: (g["position/value"][k], g["id/value"][k]) for k, s in enumerate(steps)}
lammps, imd = frames(sys.argv[1]), frames(sys.argv[2])
assert sorted(imd) == [10, 20, 30, 40], sorted(imd)
for step, (x, ids) in imd.items():
    y, lids = lammps[step]
    assert x.dtype == np.float32 and np.array_equal(x[np.argsort(ids)], y[np.argsort(lids)]), step
print("dumps: lantern-imd's positions equal lantern-lammps's float32 dump at steps 10..40")
PY
  echo "lammps: 4 images at $ranks rank(s) equal to lantern-lammps and to the float32 dump's"
  ;;
leave)
  lmp=$1
  port=$(free_port)
  # fix imd waits only while no client is connected, so once the second client is in, LAMMPS
  # runs on unhindered (0.07 s a run): a client slower to draw its first image (a sanitized
  # build) got the signal after LAMMPS had ended both runs, and the third found no port. Between
  # its runs LAMMPS now waits (60 s at most) for the file `go`, made once the second client is
  # stopped; the second then detaches in the first run or at the start of the second.
  printf 'for i in $(seq 1200); do [ -e go ] && exit 0; sleep 0.05; done; exit 1\n' > wait_go.sh
  sed -e '/external/d' -e 's/^shell .*/shell sh wait_go.sh/' "$src/in.imd" > in.case
  grep -q '^shell sh wait_go.sh' in.case || fail "in.imd has no shell line between its runs"
  (timeout 120 "$lmp" -in in.case -log none -var port "$port" -var steps 300 -var wait off \
     > lmp.txt 2>&1; echo $? > lmp.rc) &
  run_imd first 1 "127.0.0.1:$port" -lantern "$src/lj.yaml" --frames 2
  expect_rc first 0
  expect_text first/out.txt "rendered --frames 2 frames; leaving the simulation"
  [ "$(ls first/lj_*.png | wc -l)" -eq 2 ] || fail "first client: expected 2 images"
  mkdir second
  (cd second && exec "$imd" "127.0.0.1:$port" -lantern "$src/lj.yaml" > out.txt 2>&1) &
  client=$!
  for _ in $(seq 300); do ls second/lj_*.png > /dev/null 2>&1 && break; sleep 0.05; done
  kill -TERM "$client"
  wait "$client"
  echo $? > second/rc
  touch go
  expect_rc second 0
  expect_text second/out.txt "stopped by a signal"
  run_imd third 1 "127.0.0.1:$port" -lantern "$src/lj.yaml"
  expect_rc third 0
  expect_text third/out.txt "the simulation closed the connection"
  wait
  [ "$(cat lmp.rc)" = 0 ] || { cat lmp.txt; fail "LAMMPS exited $(cat lmp.rc)"; }
  [ "$(grep -c 'IMD client detached' lmp.txt)" -eq 2 ] || { cat lmp.txt; fail "LAMMPS saw no 2 detaches"; }
  [ "$(grep -c 'Loop time' lmp.txt)" -eq 2 ] || fail "LAMMPS did not finish both runs"
  for client in first second third; do  # the last image each wrote: complete and readable
    valid_png "$(ls $client/lj_*.png | tail -1)"
  done
  echo "leave: --frames, SIGTERM and the end of the run, LAMMPS finished both runs;" \
    "$(ls first/*.png second/*.png third/*.png | wc -l) images"
  ;;
example)  # examples/imd: in.melt at CI size streamed to lantern-imd with viz.yaml
  lmp=$1
  port=$(free_port)
  run_imd imd 1 "127.0.0.1:$port" -lantern "$src/../../examples/imd/viz.yaml" --every 10 &
  client=$!
  timeout 120 "$lmp" -in "$src/../../examples/imd/in.melt" -log none -var cells 4 \
    -var every 10 -var steps 30 -var port "$port" > lmp.txt 2>&1 || { cat lmp.txt; fail "lmp"; }
  wait "$client"
  expect_rc imd 0
  for s in 10 20 30; do valid_png imd/out/imd/melt_$(printf %06d $s).png; done
  echo "example: 3 images of examples/imd/in.melt"
  ;;
hostile)
  port=$(free_port)
  "$python" - "$port" > server.txt 2>&1 <<'PY' &
import socket, struct, sys
listener = socket.socket()
listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
listener.bind(("127.0.0.1", int(sys.argv[1])))
listener.listen(1)
listener.settimeout(60)
c, _ = listener.accept()
c.sendall(struct.pack("!ii", 4, 0)[:4] + struct.pack("=i", 2))  # handshake, version 2
assert struct.unpack("!ii", c.recv(8)) == (3, 0)                   # IMD_GO
energies = lambda step: struct.pack("!ii", 1, 1) + struct.pack("=i9f", step, *[0.0] * 9)
xyz = [float(v) for i in range(64) for v in (i % 4, (i // 4) % 4, i // 16)]
c.sendall(energies(5) + struct.pack("!ii", 2, 64) + struct.pack("=192f", *xyz))
c.sendall(energies(6) + struct.pack("!ii", 2, 64) + struct.pack("=100f", *xyz[:100]))
c.close()
PY
  sleep 0.3
  run_imd client "$ranks" "127.0.0.1:$port" -lantern "$src/lj.yaml"
  wait
  expect_rc client 1
  expect_text client/out.txt "frame 2's coordinates (64 atoms) (received 400 of 768 bytes): truncated"
  valid_png client/lj_000005.png
  [ "$(ls client/lj_*.png | wc -l)" -eq 1 ] || fail "expected the one image of the good frame"
  echo "hostile: exit 1 naming the truncation at $ranks rank(s), the good frame's image intact"
  ;;
gromacs)
  gmx=$1
  export GMX_MAXBACKUP=-1
  "$python" - > conf.gro <<'PY'
n, a = 8, 0.40  # 512 atoms on a simple cubic lattice, 3.2 nm box
print("argon\n%d" % n ** 3)
for i in range(n ** 3):
    x, y, z = (a * (c + 0.5) for c in (i % n, (i // n) % n, i // (n * n)))
    print("%5d%-5s%5s%5d%8.3f%8.3f%8.3f" % (i % 99999 + 1, "AR", "AR", i % 99999 + 1, x, y, z))
print("%10.5f%10.5f%10.5f" % (n * a, n * a, n * a))
PY
  "$gmx" -quiet grompp -f "$src/argon.mdp" -c conf.gro -p "$src/argon.top" -o md.tpr \
    > grompp.txt 2>&1 || { cat grompp.txt; fail "grompp failed"; }
  port=$(free_port)
  run_imd imd "$ranks" "127.0.0.1:$port" -lantern "$src/argon.yaml" --trate 10 --step-offset -1 &
  client=$!
  timeout 120 "$gmx" -quiet mdrun -s md.tpr -deffnm md -nt 1 -imdport "$port" -imdwait \
    > mdrun.txt 2>&1 || { cat mdrun.txt; fail "mdrun failed"; }
  wait "$client"
  expect_rc imd 0
  cat imd/out.txt
  expect_text imd/out.txt "11 frames rendered (steps 0..100)"
  render() {  # render DIR TOPOLOGY [TRAJECTORY]: python3 -m lantern.render into DIR
    local dir=$1
    shift
    # LANTERN_PYTHON_PRELOAD: the sanitizer runtime in a sanitized build (tests/CMakeLists.txt).
    mkdir -p "$dir" && (cd "$dir" && LD_PRELOAD=${LANTERN_PYTHON_PRELOAD:-${LD_PRELOAD:-}} \
      ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0} "$python" -m lantern.render "${@/#/../}" --quiet \
      -lantern "$src/argon.yaml" > out.txt 2>&1) || { cat "$dir/out.txt"; fail "lantern.render $*"; }
  }
  render trr conf.gro md.trr
  render xtc conf.gro md.xtc
  render gro conf.gro
  for s in 0 10 20 30 40 50 60 70 80 90 100; do
    f=ar_$(printf %06d $s).png
    cmp imd/$f trr/$f || fail "step $s: lantern-imd's image differs from GROMACS's TRR's"
    [ -f xtc/$f ] || fail "step $s: no image of the XTC"
  done
  [ -f gro/ar_000000.png ] || fail "no image of the GRO file"
  echo "gromacs: 11 images equal to the TRR's at $ranks rank(s); XTC and GRO rendered"
  ;;
*)
  echo "unknown mode $mode"
  exit 2
  ;;
esac
