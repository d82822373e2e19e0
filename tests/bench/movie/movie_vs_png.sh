#!/usr/bin/env bash
# A run writing a movie against the same run writing PNGs: mini_md's void_impact scene on 2 MPI
# ranks renders one 1024 x 1024 scene every EVERY steps, with
#   png    output: {pattern: ...}                 (PNG compressed across the ranks, the default)
#   movie  output: {movie: {file: ...}}          (h264 on rank 0's encoder thread, no images)
#   both   output: {pattern: ..., movie: {...}}
# run in turn (png, movie, both, png, ...) ROUNDS times. Prints, per variant, the medians of the
# process's wall time (lantern_close included, so the movie's last frames too), of mini_md's loop
# time and of its in-situ seconds (rank 0's time inside lantern_execute), and the median of the
# per-round ratios to png. Take the heavy lock on a shared machine:
#   flock /work/locks/heavy bash tests/bench/movie/movie_vs_png.sh build/mini_md/mini_md
# Environment: ROUNDS (5), CELLS (22), STEPS (300), EVERY (10), SIZE (1024), CODEC (h264).
# Needs bash >= 5 ($EPOCHREALTIME) and python3.
set -euo pipefail
mini_md=$(cd "$(dirname "${1:-build/mini_md/mini_md}")" && pwd)/$(basename "${1:-mini_md}")
rounds=${ROUNDS:-5} cells=${CELLS:-22} steps=${STEPS:-300} every=${EVERY:-10}
size=${SIZE:-1024} codec=${CODEC:-h264}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mpi=(mpiexec --oversubscribe -n 2)
[ "$(id -u)" = 0 ] && mpi+=(--allow-run-as-root)
export LP_NUM_THREADS=1

config() {  # config VARIANT
  local output
  case $1 in
  png) output="{pattern: 'v_{step:06d}.png'}" ;;
  movie) output="{movie: {file: 'v.mp4', codec: $codec}}" ;;
  both) output="{pattern: 'v_{step:06d}.png', movie: {file: 'v.mp4', codec: $codec}}" ;;
  esac
  cat <<YAML
schedule: {every: $every}
stats: stats.jsonl
scenes:
  - name: v
    width: $size
    height: $size
    color: {by: scalar, colormap: inferno, range: {auto: running}}
    output: $output
YAML
}

run() {  # run VARIANT ROUND -> "wall loop insitu"
  local dir=$work/$1_$2
  mkdir -p "$dir" && cd "$dir"
  config "$1" > bench.yaml
  local t0=$EPOCHREALTIME
  "${mpi[@]}" "$mini_md" --scene void_impact --cells "$cells" --steps "$steps" --thermo 0 \
    --render bench.yaml > run.log 2>&1
  local t1=$EPOCHREALTIME perf
  perf=$(grep '^PERF' run.log)
  echo "$t0 $t1 $(sed 's/.* seconds=\([^ ]*\).*/\1/' <<< "$perf") \
$(sed 's/.*insitu_seconds=\([^ ]*\).*/\1/' <<< "$perf")"
  [ "$1" = png ] || grep -q '"dropped":0' <(tail -1 stats.jsonl | tr -d ' ') ||
    echo "warning: $1 round $2 dropped frames: $(tail -1 stats.jsonl)" >&2
  cd "$work" && rm -rf "$dir"
}

variants=(png movie both)
for r in $(seq "$rounds"); do
  for v in "${variants[@]}"; do echo "$v $r $(run "$v" "$r")"; done
done > "$work/raw.txt"

echo "movie_vs_png: mini_md void_impact --cells $cells --steps $steps, one ${size}x${size} scene" \
  "every $every steps ($((steps / every + 1)) frames), 2 ranks, codec $codec, $rounds rounds"
echo "cores: $(nproc)   $(date -u +%Y-%m-%dT%H:%MZ)   load before: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/python3 - "$work/raw.txt" <<'PY'
import statistics, sys
rows = [line.split() for line in open(sys.argv[1])]
data = {}
for v, r, t0, t1, loop, insitu in rows:
    data.setdefault(v, {})[int(r)] = (float(t1) - float(t0), float(loop), float(insitu))
med = lambda xs: statistics.median(xs)
print("| variant | wall s (median) | loop s | in-situ s | wall / png (median of rounds) | in-situ / png |")
print("|---|---:|---:|---:|---:|---:|")
for v in ("png", "movie", "both"):
    rs = sorted(data[v])
    wall = [data[v][r][0] for r in rs]; loop = [data[v][r][1] for r in rs]
    insitu = [data[v][r][2] for r in rs]
    ratio = [data[v][r][0] / data["png"][r][0] for r in rs]
    iratio = [data[v][r][2] / data["png"][r][2] for r in rs]
    print(f"| {v} | {med(wall):.2f} | {med(loop):.2f} | {med(insitu):.2f} | {med(ratio):.3f} "
          f"(min {min(ratio):.3f}, max {max(ratio):.3f}) | {med(iratio):.3f} |")
PY
