#!/usr/bin/env bash
# Players on real data: the 795-frame PETS 2009 S2.L1 video (768x576) through detection,
# tracking and field mapping, timed per stage, then MOTA/MOTP/IDF1/HOTA against the PETS
# annotations, and how far those move when the detections move by half a pixel. Usage:
# bench/players.sh [BUILD_DIR] [DETECTORS...]  (default: nanodet).
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

# How far the scores move with the detections: the tracker re-run on the saved detections as
# they are and with every box's left, top, width and height moved by 0.5 px (standard deviation)
# at random (FV_BENCH_DRAWS draws, default 5; 0: none). Identity scores (IDF1) can swing far more
# than MOTA; read one run's IDF1 with this spread in mind.
stability() {  # detector ground-truth
  local det="$1" gt="$2" draws="${FV_BENCH_DRAWS:-5}" seed line
  local mota=() idf1=()
  [ "$draws" -gt 0 ] || return 0
  for seed in $(seq 0 "$draws"); do
    awk -F, -v OFS=, -v seed="$seed" '
      BEGIN { srand(seed) }
      function gauss() { return sqrt(-2 * log(1 - rand())) * cos(6.283185307 * rand()) }
      { if (seed > 0) for (i = 3; i <= 6; i++) $i += 0.5 * gauss(); print }' \
      "$OUT/det_$det.txt" >"$OUT/det_${det}_draw.txt"
    "$FV" players --camera "$OUT/pets.yaml" --video "$DATA/vtest.avi" --max-frames "$FRAMES" \
      --detections "$OUT/det_${det}_draw.txt" --min-height 45 --no-progress \
      --out "$OUT/tracks_${det}_draw.csv" >/dev/null
    line=$("$FV" eval tracks --gt "$gt" --est "$OUT/tracks_${det}_draw.csv" | grep '^MOTA')
    if [ "$seed" = 0 ]; then
      echo "tracker alone on the saved detections: ${line%%  HOTA*}"
    else
      mota+=("$(awk '{ print $2 }' <<<"$line")")
      idf1+=("$(awk '{ print $6 }' <<<"$line")")
    fi
  done
  printf '%s\n' "${mota[@]}" | sort -n | awk -v n="$draws" '{ v[NR] = $1 }
    END { printf "boxes moved by 0.5 px, %d draws: MOTA %s / %s / %s (min / median / max)", n, v[1], v[int((n + 1) / 2)], v[n] }'
  printf '%s\n' "${idf1[@]}" | sort -n | awk -v n="$draws" '{ v[NR] = $1 }
    END { printf ", IDF1 %s / %s / %s\n", v[1], v[int((n + 1) / 2)], v[n] }'
}

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
  # --camera: the tracks' field positions against the annotated boxes' feet through the same camera.
  "$FV" eval tracks --gt "$GT" --est "$OUT/tracks_$det.csv" --camera "$OUT/pets.yaml" \
    --json "$OUT/metrics_$det.json"
  stability "$det" "$GT"
done
