#!/usr/bin/env bash
# Compositing that scales with what is drawn: a fixed scene (an fcc crystal, 4 CELLS^3 atoms)
# split spatially over 2..64 ranks (oversubscribed on a small machine), composited by today's
# dense methods and by active pixels along the cost model's schedule, as the pipeline composites
# it (to the root with one sample; into row bands with SAMPLES > 1). Prints, per rank count:
# bytes and messages sent per rank (max over the ranks), active pixels per rank, the cost model's
# time, and the CPU time of each rank's own compositing work (scan, encode, merge) - never wall
# time beyond 2 ranks, where ranks share cores. At 2 ranks, root's wall time of today's method
# and of active pixels, run alternately in one process. Then the model extrapolated to 1024 and
# 4096 ranks, with its assumptions.
#
# Usage: tests/bench/composite_scaling.sh [path/to/lantern-bench-composite]
# Environment: RANKS="2 4 8 16 32 64", CELLS=40, SIZE=1024x1024, SAMPLES=1, REPS=5, RAW=file
#   (keep the raw lines), NET="2.0 12.5" (latency in us and GB/s of the assumed interconnect for
#   the extrapolation, besides the model measured here).
# Run it alone on the machine (flock /work/locks/heavy ... on a shared one).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
bin=${1:-}
if [[ -z $bin || ! -x $bin ]]; then
  bin=$(find "$repo" -name lantern-bench-composite -type f -executable 2>/dev/null | head -n 1)
fi
if [[ -z $bin ]]; then
  echo "lantern-bench-composite not found; build it or pass its path" >&2
  exit 2
fi
ranks_list=${RANKS:-2 4 8 16 32 64}
cells=${CELLS:-40}
size=${SIZE:-1024x1024}
samples=${SAMPLES:-1}
reps=${REPS:-5}
read -r net_latency net_gbps <<< "${NET:-2.0 12.5}"
mpiexec=(mpiexec --oversubscribe)
[[ $(id -u) == 0 ]] && mpiexec+=(--allow-run-as-root)
raw=${RAW:-$(mktemp)}
[[ -z ${RAW:-} ]] && trap 'rm -f "$raw"' EXIT
: > "$raw"

for p in $ranks_list; do
  LP_NUM_THREADS=1 "${mpiexec[@]}" -n "$p" "$bin" --scene="fcc:$cells" --sizes="$size" \
    --samples="$samples" --reps="$reps" --warmup=1 --check >> "$raw"
done

width=${size%x*}
height=${size#*x}
axis=1
[[ $samples == 4 ]] && axis=2
[[ $samples == 16 ]] && axis=4
pixels=$((width * height * axis * axis))

echo "lantern-bench-composite scaling: fcc ${cells}^3 cells ($((4 * cells * cells * cells)) atoms)," \
  "${size}, ${samples} sample(s) per pixel ($pixels sample pixels composited)"
echo "binary: $bin   cores: $(nproc)   $(date -u +%Y-%m-%dT%H:%MZ)   load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "command: RANKS=\"$ranks_list\" CELLS=$cells SIZE=$size SAMPLES=$samples REPS=$reps" \
  "tests/bench/composite_scaling.sh"
grep '^scene ' "$raw" | sed 's/^scene /  /'
grep '^model ' "$raw" | sed 's/^model /  measured model: /'
echo

awk -v pixels="$pixels" '
  function field(name,    i, kv) {
    for (i = 1; i <= NF; ++i) { split($i, kv, "="); if (kv[1] == name) return kv[2] }
    return ""
  }
  /^scale / {
    p = field("ranks"); c = field("config")
    if (!(p in seen)) { seen[p] = 1; order[++n] = p }
    sent[p, c] = field("bytes_sent_max"); mean[p, c] = field("bytes_sent_mean")
    msgs[p, c] = field("messages_sent_max"); recv_msgs[p, c] = field("messages_received_max")
    active[p, c] = field("active_max"); model[p, c] = field("model_ms")
    cpu[p, c] = field("cpu_ms_max"); wall[p, c] = field("wall_ms"); wall_min[p, c] = field("wall_min_ms")
    sched[p, c] = field("schedule"); meth[p, c] = field("method"); same[p, c] = field("identical"); one[p] = field("one_rank")
    if (field("target") == "bands") bands = 1
  }
  END {
    today = bands ? "dense_direct_send_bands" : "dense_binary_swap"
    now = bands ? "active_auto_bands" : "active_auto"
    printf "Bytes sent per rank (max over ranks), today (%s) vs active pixels (%s):\n", today, now
    printf "| ranks | today: bytes/rank | msgs/rank | active: schedule | bytes/rank | mean | msgs/rank | today/active | active px/rank (max) | model ms active | CPU ms/rank today | CPU ms/rank active | same image | = 1 rank |\n"
    printf "|------:|------------------:|----------:|------------------|-----------:|-----:|----------:|-------------:|---------------------:|----------------:|------------------:|-------------------:|:----------:|:--------:|\n"
    for (k = 1; k <= n; ++k) {
      p = order[k]
      ratio = (sent[p, now] > 0) ? sent[p, today] / sent[p, now] : 0
      printf "| %5d | %17.0f | %9d | %-16s | %10.0f | %4.0f | %9d | %11.1fx | %20.0f | %15.3f | %17.2f | %18.2f | %10s | %8s |\n",
        p, sent[p, today], msgs[p, today], sched[p, now], sent[p, now], mean[p, now],
        msgs[p, now], ratio, active[p, "active_binary_swap"], model[p, now], cpu[p, today], cpu[p, now],
        same[p, now], one[p]
    }
    if (!bands) {
      printf "\nActive pixels along fixed schedules (bytes sent per rank, max; messages sent; CPU ms per rank, max, of the rank'"'"'s own work):\n"
      printf "| ranks | active binary_swap | msgs | CPU ms | active direct_send | msgs | CPU ms | dense direct_send | msgs | CPU ms |\n"
      printf "|------:|-------------------:|-----:|-------:|-------------------:|-----:|-------:|------------------:|-----:|-------:|\n"
      for (k = 1; k <= n; ++k) {
        p = order[k]
        printf "| %5d | %18.0f | %4d | %6.2f | %18.0f | %4d | %6.2f | %17.0f | %4d | %6.2f |\n", p,
          sent[p, "active_binary_swap"], msgs[p, "active_binary_swap"], cpu[p, "active_binary_swap"],
          sent[p, "active_direct_send"], msgs[p, "active_direct_send"], cpu[p, "active_direct_send"],
          sent[p, "dense_direct_send"], msgs[p, "dense_direct_send"], cpu[p, "dense_direct_send"]
      }
    }
    if ((2, today) in wall) {
      printf "\nAt 2 ranks (one core each), root wall ms, median (min) of the runs, alternated in one process:\n"
      printf "  today (%s) %.3f (%.3f) ms, active pixels (%s, ran %s %s) %.3f (%.3f) ms: active/today = %.2f (%.2f)\n",
        today, wall[2, today], wall_min[2, today], now, meth[2, now], sched[2, now], wall[2, now],
        wall_min[2, now], (wall[2, today] > 0 ? wall[2, now] / wall[2, today] : 0),
        (wall_min[2, today] > 0 ? wall_min[2, now] / wall_min[2, today] : 0)
      printf "  CPU ms per rank (max): today %.3f, active pixels %.3f: active/today = %.2f\n",
        cpu[2, today], cpu[2, now], (cpu[2, today] > 0 ? cpu[2, now] / cpu[2, today] : 0)
    }
    # Active pixels per rank against the rank count: a power law a = A p^-b, least squares in
    # log-log over the rank counts >= 8 (where every axis of the split is cut).
    m = 0; sx = sy = sxx = sxy = 0
    for (k = 1; k <= n; ++k) {
      p = order[k]
      if (p < 8 || active[p, "active_binary_swap"] <= 0) continue
      x = log(p); y = log(active[p, "active_binary_swap"]); ++m; sx += x; sy += y; sxx += x * x; sxy += x * y
    }
    if (m >= 2) {
      b = -(m * sxy - sx * sy) / (m * sxx - sx * sx); A = exp((sy + b * sx) / m)
      printf "\nfit: active pixels per rank (max) = %.4g * ranks^-%.3f (rank counts >= 8)\n", A, b
      printf "FIT %.6g %.6f\n", A, b > "/dev/stderr"
    }
  }' "$raw" 2> "$raw.fit"

echo
echo "Model extrapolation (composite_cost_model.h; nothing below 'measured' ran beyond 64 ranks):"
echo "  assumptions: the busiest rank's active pixels spread evenly over the frame, the ranks'"
echo "  drawn pixels do not overlap, 8 bytes per active pixel (run-length headers left out), one"
echo "  latency per message with a round's messages concurrent, the gather to one root included;"
echo "  active pixels per rank beyond 64 ranks from the power-law fit above; CPU time per pixel"
echo "  (scan, encode, merge, dense merge) as measured at 2 ranks here, the same at every rank count."
echo "  Today = dense binary swap (every pixel sent, no scan)."
lat_here=$(awk '/^model ranks=2 /{for(i=1;i<=NF;++i){split($i,kv,"="); if(kv[1]=="latency_us") print kv[2]}}' "$raw" | head -1)
gbps_here=$(awk '/^model ranks=2 /{for(i=1;i<=NF;++i){split($i,kv,"="); if(kv[1]=="gb_per_s") print kv[2]}}' "$raw" | head -1)
cpu_here=$(awk '/^model ranks=2 /{for(i=1;i<=NF;++i){split($i,kv,"="); if(kv[1]~/_ns$/) printf " --%s=%s", kv[1], kv[2]}}' "$raw" | head -1 | sed 's/_/-/g')
echo "  CPU per pixel:${cpu_here:- not measured}"
read -r _ fit_a fit_b < <(grep '^FIT' "$raw.fit" || echo "FIT 0 0")
rm -f "$raw.fit"
active_of() {  # measured active pixels for p (max over ranks; any active schedule), else the fit
  local m
  m=$(awk -v p="$1" '/^scale /{split($2,r,"="); if (r[2]==p && $0 ~ /config=active_binary_swap /) {for(i=1;i<=NF;++i){split($i,kv,"="); if(kv[1]=="active_max") print kv[2]}}}' "$raw" | head -1)
  if [[ -n $m ]]; then echo "$m"; else awk -v a="$fit_a" -v b="$fit_b" -v p="$1" 'BEGIN{printf "%.0f", a * p ^ (-b)}'; fi
}
for net in "here $lat_here $gbps_here" "network $net_latency $net_gbps"; do
  read -r label lat gbps <<< "$net"
  [[ -z $lat ]] && continue
  echo
  echo "model with latency ${lat} us, ${gbps} GB/s ($label):"
  echo "| ranks | active px/rank | today: ms | bytes/rank | msgs | active binary_swap: ms | bytes/rank | model's schedule | ms | bytes/rank | msgs | today/active bytes |"
  echo "|------:|---------------:|----------:|-----------:|-----:|-----------------------:|-----------:|------------------|---:|-----------:|-----:|-------------------:|"
  for p in $ranks_list 1024 4096; do
    a=$(active_of "$p")
    "$bin" --model --ranks="$p" --pixels="$pixels" --active="$a" --latency-us="$lat" \
      --gb-per-s="$gbps" $cpu_here | awk -v measured="$(echo " $ranks_list " | grep -c " $p " || true)" '
      { for (i = 1; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] } }
      END {
        printf "| %5d%s | %14.0f | %9.3f | %10.0f | %4d | %22.3f | %10.0f | %-16s | %.3f | %10.0f | %4d | %17.1fx |\n",
          f["ranks"], (measured > 0 ? "" : "*"), f["active"], f["dense_ms"], f["dense_bytes_sent"],
          f["dense_messages"], f["active_binary_ms"], f["active_binary_bytes_sent"],
          f["active_schedule"], f["active_ms"], f["active_bytes_sent"], f["active_messages"],
          (f["active_bytes_sent"] > 0 ? f["dense_bytes_sent"] / f["active_bytes_sent"] : 0)
      }'
  done
  echo "(* modelled only: active pixels per rank from the fit)"
done
