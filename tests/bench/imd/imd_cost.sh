#!/bin/bash
# What rendering costs the simulation: in transit (LAMMPS's fix imd streaming to lantern-imd in
# another process) against in situ (lantern-lammps) and against LAMMPS alone, on the LAMMPS bench
# melt (examples/lammps/in.lj), one image every EVERY steps.
#
#   flock /work/locks/heavy tests/bench/imd/imd_cost.sh [BUILD] [CELLS] [STEPS] [EVERY] [ROUNDS] [SIZE]
#   defaults: build, 63 (4*63^3 = 1,000,188 atoms), 300, 100, 2, 1024
#
# Three variants of one script, each on one MPI rank (LP_NUM_THREADS=1, OMP_NUM_THREADS=1):
#   plain:   lmp, no rendering
#   in situ: lantern-lammps, `fix viz all external pf/callback EVERY 1000000000` (as its README
#            says); Lantern renders in the simulation's process
#   in situ, napply 1: the same with `pf/callback EVERY 1`: fix external then adds its (zero)
#            force array to the atoms' forces on every step (what the README first advised): a
#            pass over the forces on every step
#   imd:     lmp with `fix imd all imd PORT trate EVERY`, lantern-imd (1 rank, its own core)
#            attached over loopback: the simulation gathers and sends float32 coordinates, the
#            rendering happens in the other process
# Both renderers draw the same scene (SIZE x SIZE, radius 0.5) at steps EVERY, 2 EVERY, ... (the
# set-up step 0 is skipped by the schedule: fix imd sends nothing then). The variants alternate
# round by round.
#
# What the simulation pays is read from its own clock: LAMMPS prints its wall time after every
# step (thermo_style custom step cpu, thermo 1), so each step's duration is known. The cost of an
# image is the duration of the step that made it (fix external's callback, or fix imd's gather,
# hash and send, both in that step's post_force) minus the median of the 9 steps before it, in the
# same run, less plain's excess at the same steps (the noise of a step without an image); every
# variant rebuilds its neighbour lists every 19 steps instead of in.lj's 20, so that no image step
# is also a rebuild step (which takes several steps' time and varies by more than an image
# costs). On a shared machine the runs' times vary by tens of percent, more than an image every
# 100 steps costs, but neighbouring steps of one run share the machine's state. Reported: each
# variant's median step without an image (compared across runs, so noisy: it carries what costs
# every step, e.g. fix external adding its force array with napply 1, or lantern-imd competing
# for memory bandwidth from the other core), the median cost per image, and the slowdown at an
# image every EVERY steps, 1 + image cost / (EVERY x the run's median step). lantern-imd's own
# medians per frame (receive: header to last byte; render: lantern_execute) come from its log.
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
cells=${2:-63} steps=${3:-300} every=${4:-100} rounds=${5:-2} size=${6:-1024}
ll=$build/adaptor/lammps/lantern-lammps
imd=$build/adaptor/imd/lantern-imd
for exe in "$ll" "$imd"; do
  [ -x "$exe" ] || { echo "build $exe first"; exit 1; }
done
work=$(mktemp -d /tmp/lantern_imd_bench.XXXXXX)
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
export LP_NUM_THREADS=1 OMP_NUM_THREADS=1
cat > "$work/viz.yaml" <<YAML
schedule: {every: $every, start: $every}
scenes:
  - name: lj
    width: $size
    height: $size
    radius: 0.5
    output: {pattern: "lj_{step:06d}.png"}
YAML
# Every variant prints its wall clock after every step and rebuilds its neighbour lists every 19
# steps.
sed -e '/^run/i thermo_style    custom step cpu\nthermo          1' \
  -e 's/^\(neigh_modify .*every\) 20 /\1 19 /' "$root/examples/lammps/in.lj" > "$work/in.lj"
grep -q 'every 19 ' "$work/in.lj"
sed '/^fix *viz/d' "$work/in.lj" > "$work/in.plain"
cp "$work/in.lj" "$work/in.situ"
sed 's/^\(fix *viz .*pf\/callback\) *\${every} *1000000000/\1 ${every} 1/' "$work/in.lj" \
  > "$work/in.napply"
grep -q 'pf/callback ${every} 1$' "$work/in.napply"
sed 's/^fix *viz .*/fix             imd all imd ${port} trate ${every} nowait off/' \
  "$work/in.lj" > "$work/in.imd"
vars=(-var cells "$cells" -var every "$every" -var steps "$steps" -log none)
loop_time() { awk '/^Loop time of/ { print $4 }' "$1"; }
free_port() { /usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
atoms=$((4 * cells * cells * cells))
echo "LJ melt, $atoms atoms, $steps steps, an image every $every steps at ${size}x${size}," \
  "$rounds rounds, 1 rank each"
for r in $(seq "$rounds"); do
  d=$work/r$r && mkdir -p "$d"/plain "$d"/situ "$d"/napply "$d"/imd
  (cd "$d/plain" && lmp -in "$work/in.plain" "${vars[@]}" > out.txt)
  (cd "$d/situ" && "$ll" -in "$work/in.situ" -lantern "$work/viz.yaml" "${vars[@]}" > out.txt 2> err.txt)
  (cd "$d/napply" && "$ll" -in "$work/in.napply" -lantern "$work/viz.yaml" "${vars[@]}" \
     > out.txt 2> err.txt)
  port=$(free_port)
  (cd "$d/imd" && "$imd" "127.0.0.1:$port" -lantern "$work/viz.yaml" --every "$every" \
     2> client.txt) &
  client=$!
  (cd "$d/imd" && lmp -in "$work/in.imd" "${vars[@]}" -var port "$port" > out.txt)
  wait "$client"
  echo "round $r: plain $(loop_time "$d/plain/out.txt") s, in situ $(loop_time "$d/situ/out.txt") s," \
    "napply $(loop_time "$d/napply/out.txt") s, imd $(loop_time "$d/imd/out.txt") s;" \
    "$(tail -1 "$d/imd/client.txt")"
done
/usr/bin/python3 - "$work" "$rounds" "$steps" "$every" <<'PY'
import re, statistics, sys
work, rounds, steps, every = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
med = statistics.median
def durations(path):
    """Each step's wall seconds, from LAMMPS's thermo lines 'step cpu'."""
    clock = {}
    for line in open(path):
        fields = line.split()
        if len(fields) == 2 and fields[0].isdigit():
            clock[int(fields[0])] = float(fields[1])
    return {s: clock[s] - clock[s - 1] for s in clock if s - 1 in clock}
def costs(d):
    """Per image: its step's duration minus the median of the 9 steps before it."""
    images = [s for s in d if s % every == 0]
    return [d[s] - med([d[s - k] for k in range(1, 10)]) for s in images]
variants = {"plain": "plain lmp", "situ": "lantern-lammps in situ (pf/callback N 1000000000)",
            "napply": "lantern-lammps in situ, napply 1 (pf/callback N 1)",
            "imd": "lmp + fix imd + lantern-imd"}
runs = {v: [durations(f"{work}/r{r}/{v}/out.txt") for r in range(1, rounds + 1)] for v in variants}
step = {v: med([x for d in runs[v] for s, x in d.items() if s % every]) for v in variants}
image = {v: med([c for d in runs[v] for c in costs(d)]) for v in variants}
print(f"\n| variant | median step without an image (s) | vs plain (across runs) |"
      f" cost per image (s) | slowdown, an image every {every} steps |")
print("|---|---|---|---|---|")
for v, name in variants.items():
    # Plain's excess at the image steps (it makes no image: the noise of a step) is taken off.
    cost = image[v] - image["plain"]
    slowdown = 1 + cost / (every * step[v])
    cell = f"{cost:.3f}" if v != "plain" else f"- (its own excess: {image[v]:.3f})"
    print(f"| {name} | {step[v]:.3f} | x{step[v] / step['plain']:.3f} | {cell} |"
          f" x{slowdown:.4f} |")
client = [open(f"{work}/r{r}/imd/client.txt").read() for r in range(1, rounds + 1)]
receive = [float(re.search(r"receive ([0-9.]+) s", c).group(1)) for c in client]
render = [float(re.search(r"render ([0-9.]+) s", c).group(1)) for c in client]
situ = [open(f"{work}/r{r}/situ/err.txt").read() for r in range(1, rounds + 1)]
execute = [float(re.search(r"seconds per step: mean [0-9.]+ median ([0-9.]+)", s).group(1))
           for s in situ]
print(f"\nPer image (medians): lantern-lammps's lantern_execute {med(execute):.3f} s in the"
      f" simulation's process; lantern-imd receive {med(receive):.3f} s, render"
      f" {med(render):.3f} s in its own. Each image's cost (s): " + "; ".join(
          f"{v} " + ", ".join(f"{c:.3f}" for d in runs[v] for c in costs(d)) for v in variants))
PY
