#!/usr/bin/env bash
# Whole-pipeline timing of `fieldvision ball` (issue 8): the synthetic 4-camera, 3.2-second,
# 60 fps, 1280x960 MJPG "kick" scene, decoding included. Prints the wall time, frames/s and the
# ratio to real time (> 1: faster than real time), and the accuracy against the scene's truth.
# Usage: bench/ball_pipeline.sh [BUILD_DIR]   (the scene is cached in BUILD_DIR/bench-data)
set -euo pipefail
BUILD="${1:-build}"
FV="$BUILD/bin/fieldvision"
SCENE="$BUILD/bench-data/ball-kick"
[ -x "$FV" ] || { echo "ball_pipeline: $FV not built"; exit 1; }
if [ ! -s "$SCENE/truth.csv" ]; then
  "$FV" synth --preset kick --out "$SCENE" >/dev/null
fi
args=()
for y in "$SCENE"/*.yaml; do
  args+=(--camera "$y" --video "${y%.yaml}.avi")
done
frames=$(($(wc -l <"$SCENE/truth.csv") - 1))
start=$(date +%s.%N)
"$FV" ball "${args[@]}" --out "$SCENE/ball.csv" --no-progress >"$SCENE/ball.log"
end=$(date +%s.%N)
awk -v s="$start" -v e="$end" -v n="$frames" -v cams="${#args[@]}" 'BEGIN {
  wall = e - s; video = n / 60.0;
  printf "ball pipeline: %d cameras x %d frames (%.2f s of 60 fps video) in %.2f s wall = %.1f frames/s, %.2fx real time\n",
         cams / 4, n, video, wall, n / wall, video / wall }'
"$FV" eval ball --truth "$SCENE/truth.csv" --est "$SCENE/ball.csv" | tail -2
