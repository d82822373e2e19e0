#!/bin/bash
# A run killed with kill -9 in the middle leaves a playable movie holding every frame written so
# far: mini_md renders a movie every step; once a dozen steps are done it is killed, and ffprobe
# must decode the file and count at least the frames the last stats line reported as written.
# Fragmented MPEG-4 (.mp4) and Matroska (.mkv).
#   movie_kill_test.sh MINI_MD WORK_DIR
set -euo pipefail
mini_md=$1 work=$2
for ext in mp4 mkv; do
  dir=$work/$ext
  rm -rf "$dir" && mkdir -p "$dir" && cd "$dir"
  cat > kill.yaml <<YAML
stats: stats.jsonl
scenes:
  - name: k
    width: 201
    height: 151
    color: {by: scalar, range: {auto: running}}
    output: {movie: {file: 'k.$ext', codec: h264}}
YAML
  "$mini_md" --cells 10 --steps 1000000 --thermo 0 --render kill.yaml > run.log 2>&1 &
  pid=$!
  for _ in $(seq 1200); do
    if [ -f stats.jsonl ] && [ "$(wc -l < stats.jsonl)" -ge 12 ]; then break; fi
    kill -0 "$pid" 2> /dev/null || { echo "mini_md ended early:"; cat run.log; exit 1; }
    sleep 0.05
  done
  kill -9 "$pid"
  wait "$pid" 2> /dev/null || true
  # The frames written by the last complete stats line (a line cut by the kill is skipped).
  reported=$(/usr/bin/python3 - <<'PY'
import json
frames = 0
for line in open("stats.jsonl"):
    try:
        frames = json.loads(line)["scenes"][0]["movie"]["frames"]
    except (ValueError, KeyError):
        pass
print(frames)
PY
)
  # A kill in the middle of a write leaves a cut last cluster or fragment: ffprobe then says
  # "End of file" and exits non-zero, yet decodes every frame before it, which is what must hold.
  counted=$(ffprobe -v error -count_frames -select_streams v:0 \
    -show_entries stream=nb_read_frames -of csv=p=0 "k.$ext" || true)
  [[ "$counted" =~ ^[0-9]+$ ]] || { echo "ffprobe could not read k.$ext: '$counted'"; exit 1; }
  echo "k.$ext: killed after $(wc -l < stats.jsonl) steps; stats reported $reported frames" \
    "written, ffprobe counts $counted"
  [ "$reported" -ge 5 ] || { echo "too few frames reported"; exit 1; }
  [ "$counted" -ge "$reported" ] || { echo "frames lost by the kill"; exit 1; }
done
