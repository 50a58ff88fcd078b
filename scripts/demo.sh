#!/usr/bin/env bash
# `make demo`: renders the demo scene (4 cameras around a RoboCup MSL field, a kicked ball with
# bounces, robots, a cone, lighting change, noise, MJPG videos) with exact ground truth, then runs
# the later stages on it as they are added. Usage: scripts/demo.sh BUILD_DIR
set -euo pipefail
BUILD="${1:-build}"
FV="$BUILD/bin/fieldvision"
OUT="demo-out"
SCENE="$OUT/scene"
[ -x "$FV" ] || { echo "demo: $FV not found; run 'make build' first" >&2; exit 1; }
mkdir -p "$OUT"

echo "== 1. synthetic scene: $FV synth --preset demo --out $SCENE"
"$FV" synth --preset demo --out "$SCENE"
echo
echo "contact sheet (first frame of every camera): $SCENE/contact_sheet.png"
echo "cameras:  $SCENE/cam*.yaml    videos: $SCENE/cam*.avi (MJPG)"
echo "truth:    $SCENE/truth.csv (ball centre per frame), $SCENE/truth_2d.csv (per camera),"
echo "          $SCENE/flights.json (flights), $SCENE/scene.json (the scene, re-render with --scene)"

CAMS=()
for y in "$SCENE"/cam*.yaml; do
  CAMS+=(--camera "$y" --video "${y%.yaml}.avi")
done

echo
echo "== 2. ball in 3D from $(( ${#CAMS[@]} / 4 )) camera+video pairs: $FV ball ... --out $OUT/ball.csv"
"$FV" ball "${CAMS[@]}" --field robocup-msl --out "$OUT/ball.csv" --truth "$SCENE/truth.csv"

echo
echo "== 3. flights of the ball: $FV trajectory --in $OUT/ball.csv --out $OUT/flights.json"
"$FV" trajectory --in "$OUT/ball.csv" --out "$OUT/flights.json" --field robocup-msl \
  --images "$OUT/flights" --smoothed "$OUT/ball_smoothed.csv"
echo "truth flights for comparison: $SCENE/flights.json; pictures: $OUT/flights/"

echo
echo "== 4. coverage of the demo rig: $FV plan --camera ... --field robocup-msl --out $OUT/plan"
PLAN_CAMS=()
for y in "$SCENE"/cam*.yaml; do PLAN_CAMS+=(--camera "$y"); done
"$FV" plan "${PLAN_CAMS[@]}" --field robocup-msl --out "$OUT/plan"

echo
echo "demo: done; everything is in $OUT/"
