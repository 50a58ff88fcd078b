#!/usr/bin/env bash
# Live-pipeline latency on loopback (issue 14): four `fieldvision node` processes play the
# synthetic 4-camera 1280x960 60 fps "kick" scene in real time (--realtime, frame 0 of every
# camera at the same instant) into one `fieldvision fuse`, which measures for each 3D position the
# time from the frames' capture to the position (p50, p95). Baseline in the same run: the same
# nodes sending frames without looking for the ball (--no-detect), i.e. the cost of pacing,
# ZeroMQ, clock correction, pairing and triangulation alone. Also prints the frames the nodes
# could not keep up with (skipped by the source), where the latency goes (the nodes' source
# buffer, their work per frame, transport, pairing), the machine's load and the accuracy against
# the scene's truth. A third run has the nodes split their search for other balls (the whole
# frame every 20 frames) into two bands of rows in consecutive frames (--scan-bands 2).
# Usage: bench/ball_pipeline_live.sh [BUILD_DIR] [WIDTHxHEIGHT]   (default 1280x960; the scene is
# cached in BUILD_DIR/bench-data)
set -euo pipefail
BUILD="${1:-build}"
SIZE="${2:-1280x960}"
FV="$BUILD/bin/fieldvision"
SCENE="$BUILD/bench-data/ball-kick-q90"  # q90: MJPG frames at libjpeg quality 90
[ "$SIZE" = 1280x960 ] || SCENE="$SCENE-$SIZE"
[ -x "$FV" ] || { echo "ball_pipeline_live: $FV not built"; exit 1; }
if [ ! -s "$SCENE/truth.csv" ]; then
  "$FV" synth --preset kick --width "${SIZE%x*}" --height "${SIZE#*x}" --out "$SCENE" --quiet >/dev/null
fi
cams=("$SCENE"/*.yaml)
run() {  # name extra-node-args...
  local name="$1"
  shift
  local port=$((20000 + RANDOM % 20000))
  local cam_args=()
  for y in "${cams[@]}"; do cam_args+=(--camera "$y"); done
  "$FV" fuse --listen "tcp://127.0.0.1:$port" "${cam_args[@]}" --out "$SCENE/live_$name.csv" \
    --idle-exit 2 --no-progress >"$SCENE/fuse_$name.log" 2>&1 &
  local fuse_pid=$!
  local start_at
  start_at=$(awk -v t="$(date +%s.%N)" 'BEGIN { printf "%.3f", t + 12 }')  # every node started by then
  local pids=()
  for y in "${cams[@]}"; do
    "$FV" node --camera "$y" --video "${y%.yaml}.avi" --connect "tcp://127.0.0.1:$port" \
      --realtime --start-at "$start_at" --no-progress "$@" >"$SCENE/node_${name}_$(basename "${y%.yaml}").log" 2>&1 &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p"; done
  wait "$fuse_pid"
  local lat skipped
  lat=$(grep -o 'p50 [0-9.]* ms, p95 [0-9.]* ms' "$SCENE/fuse_$name.log" || echo "no latency")
  skipped=$(cat "$SCENE"/node_"${name}"_*.log | grep -o '[0-9]* skipped by the source' |
            awk '{ s += $1 } END { print s + 0 }')
  echo "live pipeline ($name): ${#cams[@]} nodes x 60 fps $SIZE -> fuse: latency capture -> fused frame $lat; $skipped frames skipped by slow nodes"
  tr '\r' '\n' <"$SCENE/fuse_$name.log" | grep 'where it goes' || true
  cat "$SCENE"/node_"${name}"_*.log | tr '\r' '\n' | grep -o 'work per frame.*' | sed 's/^/  node /' || true
  echo "$lat" | awk '{ print $2, $5 }' >"$SCENE/latency_$name.txt"
}
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
run transport --no-detect
run detect
run detect-2-bands --scan-bands 2  # the search for other balls in two halves, not whole frames
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
"$FV" eval ball --truth "$SCENE/truth.csv" --est "$SCENE/live_detect.csv" | tail -2
awk 'NR == FNR { b50 = $1; b95 = $2; next } { printf "detection adds: p50 %.1f ms, p95 %.1f ms (%.2fx, %.2fx the transport-only baseline)\n", $1 - b50, $2 - b95, $1 / b50, $2 / b95 }' \
  "$SCENE/latency_transport.txt" "$SCENE/latency_detect.txt"
