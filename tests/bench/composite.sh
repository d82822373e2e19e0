#!/usr/bin/env bash
# Compositing benchmark table: runs lantern-bench-composite under mpiexec at 1, 2, 4 and 8 ranks
# (oversubscribed if the machine has fewer cores) and prints, per rank count and image size, the
# median milliseconds of each method (root's wall time in composite_frames, >= 5 timed runs).
#
# Usage: tests/bench/composite.sh [path/to/lantern-bench-composite] [bench options...]
#   e.g. tests/bench/composite.sh build/tests/bench/composite/lantern-bench-composite --reps=9
# Environment: RANKS="1 2 4 8" to choose rank counts; RAW=file keeps the raw lines.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
bin=${1:-}
if [[ -n $bin && -x $bin ]]; then
  shift
else
  bin=$(find "$repo" -name lantern-bench-composite -type f -executable \
        2>/dev/null | head -n 1)
fi
if [[ -z $bin ]]; then
  echo "lantern-bench-composite not found; build it (cmake --build <dir> --target" \
       "lantern-bench-composite) or pass its path" >&2
  exit 2
fi

mpiexec=(mpiexec --oversubscribe)
[[ $(id -u) == 0 ]] && mpiexec+=(--allow-run-as-root)
raw=${RAW:-$(mktemp)}
[[ -z ${RAW:-} ]] && trap 'rm -f "$raw"' EXIT

for ranks in ${RANKS:-1 2 4 8}; do
  "${mpiexec[@]}" -n "$ranks" "$bin" "$@"
done | tee "$raw" >/dev/null

echo "lantern-bench-composite: median ms of each method (root's time, after a barrier)"
echo "binary: $bin   cores: $(nproc)   $(date -u +%Y-%m-%dT%H:%MZ)   load: $(cut -d' ' -f1-3 /proc/loadavg)"
awk '
  {
    for (i = 1; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
    key = f["ranks"] SUBSEP f["size"]
    if (!(key in seen)) { seen[key] = 1; rows[++nrows] = key }
    ms[key, f["method"]] = f["median_ms"]
    if (f["method"] == "auto") picked[key] = f["ran"]
  }
  END {
    printf "| %5s | %-9s | %10s | %14s | %11s | %11s | %10s | %-14s |\n", "ranks", "size",
           "reduce64", "reduce_scatter", "binary_swap", "direct_send", "auto", "auto ran"
    printf "|------:|-----------|-----------:|---------------:|------------:|------------:|-----------:|----------------|\n"
    for (r = 1; r <= nrows; ++r) {
      key = rows[r]; split(key, parts, SUBSEP)
      printf "| %5s | %-9s | %10s | %14s | %11s | %11s | %10s | %-14s |\n", parts[1], parts[2],
             ms[key, "reduce64"], ms[key, "reduce_scatter"], ms[key, "binary_swap"],
             ms[key, "direct_send"], ms[key, "auto"], picked[key]
    }
  }' "$raw"
