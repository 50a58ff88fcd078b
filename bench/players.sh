#!/usr/bin/env bash
# Players on real data: the 795-frame PETS 2009 S2.L1 video (768x576) through detection,
# tracking and field mapping, timed per stage, then MOTA/MOTP/IDF1/HOTA against the PETS
# annotations. Usage: bench/players.sh [BUILD_DIR] [DETECTORS...]  (default: nanodet).
# FV_BENCH_FRAMES=N limits the frames (e.g. for the slow hog detector). The detections are saved
# to BUILD/bench-players/det_DETECTOR.txt: `fieldvision players ... --detections` on them re-runs
# the tracker alone in about a second.
set -euo pipefail
BUILD="${1:-build}"
shift || true
DETECTORS=("$@")
[ ${#DETECTORS[@]} -eq 0 ] && DETECTORS=(nanodet)
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
DATA="$ROOT/../shared/data/pets2009-s2l1"
FV="$BUILD/bin/fieldvision"
if [ ! -f "$DATA/vtest.avi" ]; then
  echo "players bench: $DATA absent; skipped"
  exit 0
fi
OUT="$BUILD/bench-players"
mkdir -p "$OUT"
"$FV" calibrate import --tsai "$DATA/View_001.xml" --out "$OUT/pets.yaml" --name View_001
"$FV" eval import-pets --xml "$DATA/PETS2009-S2L1.xml" --out "$OUT/gt.csv"
FRAMES="${FV_BENCH_FRAMES:-0}"
for det in "${DETECTORS[@]}"; do
  echo "== detector $det (frames: ${FRAMES/#0/all}, $(nproc) cores)"
  start=$(date +%s%N)
  # The PETS annotations cover the people in front of the background path (boxes of 52 px and
  # taller); --min-height 45 leaves out the smaller people walking beyond it.
  "$FV" players --camera "$OUT/pets.yaml" --video "$DATA/vtest.avi" --out "$OUT/tracks_$det.csv" \
    --detector "$det" --max-frames "$FRAMES" --min-height 45 --no-progress \
    --save-detections "$OUT/det_$det.txt"
  end=$(date +%s%N)
  echo "wall time: $(( (end - start) / 1000000 )) ms"
  if [ "$FRAMES" = 0 ]; then
    GT="$OUT/gt.csv"
  else
    # Frames are numbered from 1 in both files (MOTChallenge).
    awk -F, -v n="$FRAMES" 'NR == 1 || $1 <= n' "$OUT/gt.csv" > "$OUT/gt_$FRAMES.csv"
    GT="$OUT/gt_$FRAMES.csv"
  fi
  "$FV" eval tracks --gt "$GT" --est "$OUT/tracks_$det.csv" --json "$OUT/metrics_$det.json"
done
