#!/usr/bin/env bash
# Whole-pipeline timing of `fieldvision ball` (issue 8): the synthetic 4-camera, 3.2-second,
# 60 fps, 1280x960 MJPG "kick" scene, decoding included. Prints the wall time, frames/s and the
# ratio to real time (> 1: faster than real time), and the accuracy against the scene's truth.
# Usage: bench/ball_pipeline.sh [BUILD_DIR]   (the scene is cached in BUILD_DIR/bench-data)
set -euo pipefail
BUILD="${1:-build}"
FV="$BUILD/bin/fieldvision"
SCENE="$BUILD/bench-data/ball-kick-q90"  # q90: MJPG frames at libjpeg quality 90
[ -x "$FV" ] || { echo "ball_pipeline: $FV not built"; exit 1; }
if [ ! -s "$SCENE/truth.csv" ]; then
  "$FV" synth --preset kick --out "$SCENE" >/dev/null
fi
args=()
for y in "$SCENE"/*.yaml; do
  args+=(--camera "$y" --video "${y%.yaml}.avi")
done
frames=$(($(wc -l <"$SCENE/truth.csv") - 1))
# One run per mode: the default (each camera tracks the ball and decodes MJPG only around it)
# and the baseline that searches and decodes every frame whole; ratios against the baseline.
run() {  # mode-name extra-args...
  local name="$1"
  shift
  local start end
  start=$(date +%s.%N)
  /usr/bin/time -f "%U %S" -o "$SCENE/time_$name.txt" \
    "$FV" ball "${args[@]}" "$@" --out "$SCENE/ball_$name.csv" --no-progress >"$SCENE/ball_$name.log"
  end=$(date +%s.%N)
  awk -v s="$start" -v e="$end" -v n="$frames" -v cams="$((${#args[@]} / 4))" -v name="$name" \
    -v cpu="$(awk '{print $1 + $2}' "$SCENE/time_$name.txt")" 'BEGIN {
    wall = e - s; video = n / 60.0;
    printf "ball pipeline (%s): %d cameras x %d frames (%.2f s of 60 fps video) in %.2f s wall, %.2f s CPU = %.1f frames/s, %.2fx real time\n",
           name, cams, n, video, wall, cpu, n / wall, video / wall }'
  awk -v s="$start" -v e="$end" 'BEGIN { print e - s }' >"$SCENE/wall_$name.txt"
  # The tracked modes' decoding work: camera frames searched in a window, and whole.
  grep -oE '[0-9]+ camera frames searched in a window around the ball, [0-9]+ whole' \
    "$SCENE/ball_$name.log" | sed 's/^/  /' || true
  "$FV" eval ball --truth "$SCENE/truth.csv" --est "$SCENE/ball_$name.csv" | tail -2
}
run whole --whole-frames
run no-background --no-background
run tracked
awk -v w="$(cat "$SCENE/wall_whole.txt")" -v t="$(cat "$SCENE/wall_tracked.txt")" \
  -v n="$(cat "$SCENE/wall_no-background.txt")" 'BEGIN {
  printf "tracked vs whole frames: %.2fx faster (wall); the backgrounds cost %.0f %% (wall)\n",
         w / t, 100 * (t / n - 1) }'
