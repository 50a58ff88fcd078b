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

# == 2. ball: find the ball in every video and triangulate it (added by the ball/recon work).
#    e.g. "$FV" ball --camera "$SCENE/cam1.yaml" --video "$SCENE/cam1.avi" ... --out "$OUT/ball.csv"
#    then "$FV" eval ball --truth "$SCENE/truth.csv" --in "$OUT/ball.csv"

# == 3. trajectory: fit flights to the 3D ball track (added by the flight-fitting work).
#    e.g. "$FV" trajectory --in "$OUT/ball.csv" --out "$OUT/flights.json" (compare with
#    "$SCENE/flights.json")

# == 4. plan: coverage of the demo rig (added by the camera-planning work).
#    e.g. "$FV" plan --camera "$SCENE/cam1.yaml" ... --field robocup-msl --out "$OUT/plan"

# == 5. players: track people in the players preset (added by the player-tracking work).
#    e.g. "$FV" synth --preset players --out "$OUT/players-scene" and
#    "$FV" players --camera "$OUT/players-scene/side.yaml" --video "$OUT/players-scene/side.avi" ...

echo
echo "demo: done; everything is in $OUT/"
