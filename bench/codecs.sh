#!/usr/bin/env bash
# What a camera's compression costs `fieldvision ball`: the same renders written as Motion-JPEG
# (libjpeg quality 90, every frame a JPEG: the baseline) and as H.264 (`synth --format mp4`, the
# x264 encoder's default quality: about 1 Mbit/s for these renders), each camera's background
# read as the codec allows (camera_background.h). Prints, per scene and codec, the frames placed, the
# 3D error against the truth and the wall time, the H.264 run's ratios to the baseline, and H.264
# without the background (what reading it in order buys).
# Usage: bench/codecs.sh [BUILD_DIR]   (scenes cached in BUILD_DIR/bench-data)
set -euo pipefail
BUILD="${1:-build}"
FV="$BUILD/bin/fieldvision"
DATA="$BUILD/bench-data/codecs"
[ -x "$FV" ] || { echo "codecs: $FV not built"; exit 1; }
mkdir -p "$DATA"

# scene-name preset seed colour
# (three low-sun statics: 16 frames each, one seed alone swings by a frame or a few mm)
scenes=("kick kick 1 orange" "low-sun-kick low-sun-kick 1 yellow" "low-sun low-sun 1 yellow"
  "low-sun-2 low-sun 2 yellow" "low-sun-3 low-sun 3 yellow")

run() {  # dir ext colour tag [ball options] -> prints "found mean p95 wall"
  local dir="$1" ext="$2" colour="$3" tag="$4" args=() start end
  shift 4
  for y in "$dir"/*.yaml; do args+=(--camera "$y" --video "${y%.yaml}.$ext"); done
  start=$(date +%s.%N)
  "$FV" ball "${args[@]}" --color "$colour" --field robocup-msl --out "$dir/ball_$tag.csv" \
    --no-progress "$@" >"$dir/ball_$tag.log"
  end=$(date +%s.%N)
  "$FV" eval ball --truth "$dir/truth.csv" --est "$dir/ball_$tag.csv" | awk -v s="$start" \
    -v e="$end" '/^matched/ { match($0, /found [0-9]+ of [0-9]+/); found = substr($0, RSTART + 6, RLENGTH - 6); sub(/ of /, "/", found) }
    /^error mm/ { mean = $4; p95 = $8 }
    END { sub(/,/, "", mean); sub(/,/, "", p95); printf "%s %s %s %.2f\n", found, mean, p95, e - s }'
}

for s in "${scenes[@]}"; do
  read -r name preset seed colour <<<"$s"
  for fmt in avi mp4; do
    dir="$DATA/$name-$fmt"
    if [ ! -s "$dir/truth.csv" ]; then
      if ! "$FV" synth --preset "$preset" --seed "$seed" --format "$fmt" --out "$dir" --quiet \
        >"$DATA/synth.log" 2>&1; then
        echo "codecs: $name as $fmt not rendered: $(tail -1 "$DATA/synth.log")"
        continue 2
      fi
    fi
  done
  read -r f0 m0 p0 w0 <<<"$(run "$DATA/$name-avi" avi "$colour" avi)"
  read -r f1 m1 p1 w1 <<<"$(run "$DATA/$name-mp4" mp4 "$colour" mp4)"
  read -r f2 m2 p2 w2 <<<"$(run "$DATA/$name-mp4" mp4 "$colour" mp4-no-background --no-background)"
  printf "%-13s Motion-JPEG: found %s, mean %s mm, p95 %s mm, %s s | H.264: found %s, mean %s mm, p95 %s mm, %s s\n" \
    "$name" "$f0" "$m0" "$p0" "$w0" "$f1" "$m1" "$p1" "$w1"
  awk -v m0="$m0" -v m1="$m1" -v p0="$p0" -v p1="$p1" -v w0="$w0" -v w1="$w1" -v n="$name" 'BEGIN {
    printf "%-13s H.264 / Motion-JPEG: mean error %.2fx, p95 %.2fx, wall time %.2fx\n", n, m1 / m0, p1 / p0, w1 / w0 }'
  printf "%-13s H.264 without the background (--no-background): found %s, mean %s mm, p95 %s mm, %s s\n" \
    "$name" "$f2" "$m2" "$p2" "$w2"
done
