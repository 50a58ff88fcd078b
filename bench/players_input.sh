#!/usr/bin/env bash
# NanoDet's input size on HD video: the synthetic `players` scene (8 people, 250 frames at 25
# frames/s) rendered at SIZE (default 1920x1080), tracked with the default input (from the frame:
# half its width, 416..960 px) and with the old fixed 416 px as the baseline in the same run;
# prints wall time, the ratio, MOTA/IDF1 against the scene's truth and the ids and teams found
# (--teams). Usage: bench/players_input.sh [BUILD_DIR] [WIDTHxHEIGHT]
set -euo pipefail
BUILD="${1:-build}"
SIZE="${2:-1920x1080}"
FV="$BUILD/bin/fieldvision"
OUT="$BUILD/bench-players-input/$SIZE"
mkdir -p "$OUT"
if [ ! -f "$OUT/side.avi" ]; then
  "$FV" synth --preset players --out "$OUT" --width "${SIZE%x*}" --height "${SIZE#*x}" --quiet \
    > /dev/null
fi
# The truth as MOTChallenge ground truth (1-based frames), people at least 20 % visible.
awk -F, 'NR == 1 { print "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s"; next }
         $8 >= 0.2 { print $1 + 1 "," $3 "," $4 "," $5 "," $6 "," $7 ",1,,," }' \
  "$OUT/players_2d.csv" > "$OUT/gt.csv"
declare -A WALL
for w in 416 0; do
  start=$(date +%s%N)
  "$FV" players --camera "$OUT/side.yaml" --video "$OUT/side.avi" --field robocup-msl --teams \
    --no-progress --input-width "$w" --out "$OUT/tracks_$w.csv" > "$OUT/players_$w.log"
  end=$(date +%s%N)
  WALL[$w]=$(( (end - start) / 1000000 ))
  label=$([ "$w" = 0 ] && echo "default (from the frame)" || echo "fixed $w px (baseline)")
  echo "== input $label: ${WALL[$w]} ms wall, $(nproc) cores"
  grep -o '[0-9]* tracks ([^)]*)' "$OUT/players_$w.log" | head -1
  ids=$(tail -n +2 "$OUT/tracks_$w.csv" | cut -d, -f2 | sort -u | wc -l)
  teams=$(tail -n +2 "$OUT/tracks_$w.csv.teams.csv" | cut -d, -f2 | sort | uniq -c | tr '\n' ' ')
  echo "ids: $ids; ids per team (count team): $teams"
  "$FV" eval tracks --gt "$OUT/gt.csv" --est "$OUT/tracks_$w.csv" | head -1
done
awk -v a="${WALL[0]}" -v b="${WALL[416]}" 'BEGIN { printf "time ratio default / 416: %.2fx\n", a / b }'
