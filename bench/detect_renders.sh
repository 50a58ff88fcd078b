#!/usr/bin/env bash
# The ball detector on the hard renders (issue 12): every camera of the low-sun static scenes
# (seeds 1-3, 16 placements each, a printed yellow ball, the sun 30 deg up) scored by
# `eval detect` against the scenes' own truth_2d.csv, whole frames, views with the ball at least
# 70 % visible; the baseline is the same rig and placements in plain light (`static`, orange).
# Prints per scene the views where the ball is ranked first, accepted (first or not) and has a
# candidate, the centre error of the first-ranked hits, and the low-sun/plain ratio of that error.
# Usage: bench/detect_renders.sh [BUILD_DIR] [colour|both]  (scenes cached in BUILD/bench-data)
set -euo pipefail
BUILD="${1:-build}"
DETECTOR="${2:-colour}"
FV="$BUILD/bin/fieldvision"
[ -x "$FV" ] || { echo "detect_renders: $FV not built"; exit 1; }
DATA="$BUILD/bench-data"
OUT="$DATA/detect-renders-$DETECTOR"
mkdir -p "$OUT"
score() {  # preset seed colour -> "first accepted candidate views median_px p90_px"
  local preset="$1" seed="$2" colour="$3" scene="$DATA/$1-seed$2"
  [ -s "$scene/truth_2d.csv" ] || "$FV" synth --preset "$preset" --seed "$seed" --out "$scene" \
    --quiet >/dev/null
  local rows=()
  for cam in "$scene"/cam*.yaml; do
    local name
    name=$(basename "$cam" .yaml)
    "$FV" eval detect --video "$scene/$name.avi" --labels "$scene/truth_2d.csv" --camera "$cam" \
      --color "$colour" --field robocup-msl --detector "$DETECTOR" --no-progress --list 0 \
      --out "$OUT/$preset-$seed-$name.csv" >"$OUT/$preset-$seed-$name.txt"
    rows+=("$OUT/$preset-$seed-$name.csv")
  done
  # Columns of eval detect --out: image,boxes,detected,hit,u,v,radius_px,score,centre_err_px,
  # candidate_on_ball,accepted_on_ball,...
  local counts errors
  counts=$(awk -F, 'FNR > 1 && $2 > 0 { n++; first += $4; cand += $10; acc += $11 }
                    END { printf "%d %d %d %d", first, acc, cand, n }' "${rows[@]}")
  errors=$(awk -F, 'FNR > 1 && $4 == 1 { print $9 }' "${rows[@]}" | sort -g |
    awk '{ e[NR] = $1 } END { if (NR == 0) { print "0 0"; exit }
           printf "%.3f %.3f", e[int((NR + 1) / 2)], e[int(0.9 * NR + 0.999)] }')
  echo "$counts $errors"
}
printf "%-22s %6s %9s %10s %6s %12s %9s\n" scene first accepted candidate views "median px" "p90 px"
for seed in 1 2 3; do
  read -r f a c n m p <<<"$(score static "$seed" orange)"
  read -r lf la lc ln lm lp <<<"$(score low-sun "$seed" yellow)"
  printf "%-22s %6d %9d %10d %6d %12.3f %9.3f\n" "static seed $seed" "$f" "$a" "$c" "$n" "$m" "$p"
  printf "%-22s %6d %9d %10d %6d %12.3f %9.3f\n" "low-sun seed $seed" "$lf" "$la" "$lc" "$ln" \
    "$lm" "$lp"
  awk -v a="$lm" -v b="$m" -v s="$seed" 'BEGIN { if (b > 0) printf "  seed %d: low-sun / plain centre error (median) %.2fx\n", s, a / b }'
done
