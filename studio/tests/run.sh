#!/usr/bin/env bash
# Browser tests of the studio (CTest `studio_browser`): renders a small synthetic scene, runs the
# ball pipeline on it, starts `fieldvision studio` there on a free loopback port and drives
# Debian's chromium with playwright-core (tests/browser.mjs). Screenshots land in OUT_DIR.
# Exit 77 (CTest: skipped) only when node or chromium is absent.
# Usage: run.sh FIELDVISION OUT_DIR
set -euo pipefail
FV="$(realpath "$1")"
OUT="$(realpath -m "$2")"
STUDIO="$(cd "$(dirname "$0")/.." && pwd)"
CHROMIUM="${FV_CHROMIUM:-/usr/bin/chromium}"
if ! command -v node >/dev/null 2>&1; then
  echo "SKIP: node not found: the studio's browser tests need Node.js (scripts/install-deps.sh installs it)"
  exit 77
fi
if [ ! -x "$CHROMIUM" ]; then
  echo "SKIP: $CHROMIUM not found: the studio's browser tests need Debian's chromium (scripts/install-deps.sh installs it)"
  exit 77
fi
if [ ! -d "$STUDIO/node_modules/playwright-core" ] || [ ! -f "$STUDIO/dist/index.html" ]; then
  bash "$STUDIO/build.sh"
fi
[ -d "$STUDIO/node_modules/playwright-core" ] || { echo "FAIL: playwright-core is not installed (npm ci in studio/ failed)"; exit 1; }
[ -f "$STUDIO/dist/index.html" ] || { echo "FAIL: the studio front end is not built (studio/build.sh)"; exit 1; }

START=$(date +%s.%N)
rm -rf "$OUT"
mkdir -p "$OUT/work"
W="$OUT/work"
# The scene: 4 cameras around a RoboCup field, a kicked ball; 40 frames at 640x480.
"$FV" synth --preset kick --seed 1 --frames 40 --width 640 --height 480 --quiet --out "$W/scene" >"$OUT/synth.log"
args=()
for c in 1 2 3 4; do args+=(--camera "$W/scene/cam$c.yaml" --video "$W/scene/cam$c.avi"); done
"$FV" ball "${args[@]}" --out "$W/ball.csv" >"$OUT/ball.log" 2>&1
"$FV" trajectory --in "$W/ball.csv" --out "$W/flights.json" >"$OUT/trajectory.log" 2>&1 || true
[ -f "$W/flights.json" ] || echo "[]" >"$W/flights.json"
# Player tracks for the tactical board (TRACKS.csv layout, 1-based frames, with the boxes in the
# scene's side camera and the team) from a players scene's truth; its video is shown beside the board.
"$FV" synth --preset players --seed 1 --frames 30 --width 320 --height 240 --quiet --out "$W/players" >"$OUT/synth_players.log"
awk -F, 'FNR == 1 { next }
         FILENAME ~ /_2d/ { box[$1 "," $3] = $4 "," $5 "," $6 "," $7; next }
         { k = $1 "," $3; b = (k in box) ? box[k] : ",,,";
           printf "%d,%d,%s,1,%s,%s,%s,%s\n", $1 + 1, $3, b, $5, $6, $2, $4 }' \
  "$W/players/players_2d.csv" "$W/players/players.csv" |
  { echo "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s,team"; cat; } >"$W/TRACKS.csv"

# Real chessboard views for the intrinsics section (OpenCV's samples in ../shared/data), when there.
BOARDS="$STUDIO/../../shared/data/opencv-chessboard"
if [ -d "$BOARDS" ]; then
  mkdir -p "$W/boards"
  cp "$BOARDS"/left*.jpg "$W/boards/"
  export FV_BOARDS_REFERENCE="$BOARDS/left_intrinsics.yml"
fi

echo "  (scenes and ball track made: $(awk "BEGIN { printf \"%.1f\", $(date +%s.%N) - $START }") s)"
cd "$W"
"$FV" studio --port 0 >"$OUT/server.log" 2>&1 &
SERVER=$!
trap 'kill $SERVER 2>/dev/null || true; wait $SERVER 2>/dev/null || true' EXIT
URL=""
for _ in $(seq 100); do
  URL="$(grep -o 'http://127.0.0.1:[0-9]*/' "$OUT/server.log" | head -1 || true)"
  [ -n "$URL" ] && break
  kill -0 $SERVER 2>/dev/null || { echo "FAIL: the studio server exited:"; cat "$OUT/server.log"; exit 1; }
  sleep 0.1
done
[ -n "$URL" ] || { echo "FAIL: the studio server did not start"; cat "$OUT/server.log"; exit 1; }
node "$STUDIO/tests/browser.mjs" "$URL" "$OUT" "$FV"
