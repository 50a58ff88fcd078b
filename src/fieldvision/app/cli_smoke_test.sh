#!/usr/bin/env bash
# The program's contract at the command line: every subcommand of CONTRACT.md has --help, bad
# input gives a one-line error and a non-zero exit.
set -u
FV="$1"
TMP="$2"
rm -rf "$TMP" && mkdir -p "$TMP"
fail=0
check() {  # check NAME EXPECTED_EXIT(0|nonzero) CMD...
  local name="$1" expect="$2"
  shift 2
  "$@" >"$TMP/out" 2>"$TMP/err"
  local rc=$?
  if [ "$expect" = 0 ] && [ $rc -ne 0 ]; then
    echo "FAIL $name: exit $rc"; cat "$TMP/err"; fail=1
  elif [ "$expect" = nonzero ] && [ $rc -eq 0 ]; then
    echo "FAIL $name: exit 0, expected an error"; fail=1
  elif [ "$expect" = nonzero ] && [ "$(wc -l <"$TMP/err")" -ne 1 ]; then
    echo "FAIL $name: error is not one line:"; cat "$TMP/err"; fail=1
  else
    echo "ok   $name"
  fi
}
for c in synth ball trajectory plan players stats detect "calibrate intrinsics" \
         "calibrate extrinsics" "calibrate refine" "field show" "field draw" "eval ball" \
         "color learn" "calibrate check" "calibrate rig" "eval tracks" "eval detect" \
         "eval import-pets" "calibrate multi" "calibrate import" "calibrate export" \
         "calibrate compare" node fuse studio tracks; do
  check "$c --help" 0 $FV $c --help
  # A negated flag reads as its name (CLI11 wrote "--no-progress{false}").
  grep -q "{false}\|{true}" "$TMP/out" && { echo "FAIL $c --help: a flag's {value}"; fail=1; }
done
check "field show" 0 $FV field show robocup-msl
# OpenCV's codecs (a plugin, codecs.h) load only for a command that reads or writes images.
if LD_DEBUG=files $FV field show robocup-msl 2>&1 | grep -q "libopencv_videoio\|libopencv_imgcodecs"; then
  echo "FAIL field show loaded OpenCV's imgcodecs or videoio"; fail=1
else
  echo "ok   codecs not loaded by field show"
fi
check "field draw" 0 $FV field draw fifa --out "$TMP/fifa.png"
[ -s "$TMP/fifa.png" ] || { echo "FAIL field draw wrote nothing"; fail=1; }
check "unknown field" nonzero $FV field show rugby
check "bad output folder" nonzero $FV field draw fifa --out /nonexistent/dir/x.png
check "ball: missing camera file" nonzero $FV ball --camera "$TMP/none.yaml" --video "$TMP/none.avi" \
  --camera "$TMP/none2.yaml" --video "$TMP/none2.avi" --out "$TMP/ball.csv"
check "trajectory: missing track" nonzero $FV trajectory --in "$TMP/none.csv" --out "$TMP/f.json"
check "plan: missing rig" nonzero $FV plan --rig "$TMP/none.json" --out "$TMP/plan"
check "extrinsics: missing camera" nonzero $FV calibrate extrinsics --camera "$TMP/none.yaml" \
  --points "$TMP/none.csv" --out "$TMP/c.yaml"
printf 'frame,time_s,x_m,y_m,z_m\n0,0,1,2,nan\n' > "$TMP/nan.csv"
check "ball: --det-sigma without --detections" nonzero $FV ball --camera "$TMP/c1.yaml" \
  --video "$TMP/v.avi" --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" \
  --det-sigma 3
check "ball: --out a device" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out /dev/null
[ -c /dev/null ] || { echo "FAIL ball: /dev/null replaced"; fail=1; }
printf 'frame,time_s,x_m,y_m,z_m\n0,0,1e300,2,0.1\n' > "$TMP/huge_truth.csv"
check "ball: --truth position 1e300" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" --truth "$TMP/huge_truth.csv"
grep -q "huge_truth.csv:2" "$TMP/err" || { echo "FAIL ball: truth line not named"; fail=1; }
check "ball: --draw with --sync time" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" --draw "$TMP/drawn_ball" --sync time
grep -q "needs --sync frame" "$TMP/err" || { echo "FAIL ball: --draw's sync not named"; fail=1; }
check "ball: --draw with a live source" nonzero $FV ball --camera "$TMP/c1.yaml" --video rtsp://x \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" --draw "$TMP/drawn_ball"
grep -q "rtsp://x" "$TMP/err" || { echo "FAIL ball: --draw's live source not named"; fail=1; }
check "ball: --draw with --out a folder" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP" --draw "$TMP/drawn_ball"
[ ! -e "$TMP/drawn_ball" ] || { echo "FAIL ball: a failed run left its --draw folder"; fail=1; }
printf 'frame,time_s,x_m,y_m,z_m\n' > "$TMP/empty_truth.csv"
check "ball: --truth header only" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" --truth "$TMP/empty_truth.csv"
grep -q "no rows" "$TMP/err" || { echo "FAIL ball: empty truth not named"; fail=1; }
mkdir -p "$TMP/imgs" && $FV field draw fifa --out "$TMP/imgs/a.png" >/dev/null
cp "$TMP/imgs/a.png" "$TMP/a_copy.png"
check "eval detect: --out an image it reads" nonzero $FV eval detect --video "$TMP/imgs" \
  --out "$TMP/imgs/a.png" --no-progress
cmp -s "$TMP/imgs/a.png" "$TMP/a_copy.png" || { echo "FAIL eval detect: image overwritten"; fail=1; }
mkdir -p "$TMP/dimgs" && cp "$TMP/imgs/a.png" "$TMP/dimgs/a.png" && : > "$TMP/dimgs/a.txt"
check "eval detect: --draw-misses inside the images' folder" nonzero $FV eval detect \
  --video "$TMP/dimgs" --draw-misses "$TMP/dimgs/drawn" --detector colour --no-progress
[ ! -e "$TMP/dimgs/drawn" ] || { echo "FAIL eval detect: --draw-misses folder made"; fail=1; }
grep -q "lies in the images' folder" "$TMP/err" || { echo "FAIL eval detect: folder not named"; fail=1; }
check "eval detect: --draw-misses" 0 $FV eval detect --video "$TMP/dimgs" \
  --draw-misses "$TMP/drawn" --detector colour --no-progress
grep -q "drew 0 misses" "$TMP/out" || { echo "FAIL eval detect: drawings not said"; fail=1; }
# A rendered frame with its ball's YOLO box (the camera where the ball looks largest).
mkdir -p "$TMP/limgs" "$TMP/nolabels"
"$FV" synth --preset static --frames 1 --width 1280 --height 960 --format png --out "$TMP/lsyn" \
  --quiet >/dev/null 2>&1 || { echo "FAIL synth of the label fixture"; fail=1; }
read -r lcam lbox < <(awk -F, 'NR > 1 && $5 > r { r = $5; c = $2;
  b = sprintf("%.6f %.6f %.6f %.6f", $3 / 1280, $4 / 960, 2 * $5 / 1280, 2 * $5 / 960) }
  END { print c, b }' "$TMP/lsyn/truth_2d.csv")
cp "$TMP/lsyn/$lcam/00000.png" "$TMP/limgs/a.png"
check "color learn: --labels without a label file" nonzero $FV color learn --video "$TMP/limgs" \
  --labels "$TMP/nolabels" --out "$TMP/l.json"
grep -q "none of the 1 images has a label file" "$TMP/err" || {
  echo "FAIL color learn: missing labels not named"; fail=1; }
printf '0 %s\n' "$lbox" > "$TMP/limgs/a.txt"
check "color learn: --labels and --roi" nonzero $FV color learn --video "$TMP/limgs" \
  --labels "$TMP/limgs" --roi 1,1,4,4 --out "$TMP/l.json"
check "color learn: --labels, the class forced" 0 $FV color learn --video "$TMP/limgs" \
  --labels "$TMP/limgs" --force --out "$TMP/l.json"
grep -q "learned from 1 boxes in 1 of the 1 frames with a ball" "$TMP/out" || {
  echo "FAIL color learn: --labels report"; fail=1; }
# --detector auto: both on still images where the model was built (else colour, with a warning).
check "detect: auto on a still image" 0 $FV detect --video "$TMP/limgs/a.png" --out "$TMP/da.csv" \
  --no-progress
head -1 "$TMP/out" | grep -q "^detector: both (auto: still images\|^detector: colour (auto: still images, but no NanoDet model" || {
  echo "FAIL detect: the auto detector not said"; fail=1; }
# A missing input: its error alone, no "detector:" line before it.
for c in "detect" "eval detect --labels $TMP/limgs"; do
  # shellcheck disable=SC2086  # the command's words
  check "$c: auto on a missing image" nonzero $FV $c --video "$TMP/limgs/none.png" \
    --out "$TMP/dm.csv" --no-progress
  grep -q "none.png" "$TMP/err" || { echo "FAIL $c: the missing image not named"; fail=1; }
  [ ! -s "$TMP/out" ] || { echo "FAIL $c: printed before its error: $(head -1 "$TMP/out")"; fail=1; }
done
check "ball: --detector auto" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" --detector auto
grep -q -- "--detector" "$TMP/err" || { echo "FAIL ball: --detector auto not named"; fail=1; }
check "ball: one camera" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --out "$TMP/b.csv"
grep -q "one camera" "$TMP/err" || { echo "FAIL ball: one camera not named"; fail=1; }
check "ball: a video twice" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v.avi" --out "$TMP/b.csv"
check "ball: --write-detections for one of two cameras" nonzero $FV ball --camera "$TMP/c1.yaml" \
  --video "$TMP/v.avi" --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" \
  --write-detections "$TMP/d1.csv"
grep -q "write-detections" "$TMP/err" || { echo "FAIL ball: --write-detections count not named"; fail=1; }
check "ball: --tolerance 1e300" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" --tolerance 1e300
check "ball: --inlier-px nan" nonzero $FV ball --camera "$TMP/c1.yaml" --video "$TMP/v.avi" \
  --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" --inlier-px nan
check "detect: --ball-diameter nan" nonzero $FV detect --video "$TMP/v.avi" --out "$TMP/d.csv" \
  --ball-diameter nan
grep -q -- "--ball-diameter" "$TMP/err" || { echo "FAIL detect: nan diameter not named"; fail=1; }
check "detect: --ball-diameter 1e300" nonzero $FV detect --video "$TMP/v.avi" --out "$TMP/d.csv" \
  --ball-diameter 1e300
# Options checked together or by their own rules are named as options, not as internal fields.
named() {  # named NAME OPTION CMD...: one-line error naming OPTION
  local name="$1" option="$2"
  shift 2
  check "$name" nonzero "$@"
  grep -q -- "$option" "$TMP/err" || { echo "FAIL $name: $option not named"; fail=1; }
}
named "detect: --min-radius above --max-radius" --max-radius $FV detect --video "$TMP/v.avi" \
  --out "$TMP/d.csv" --min-radius 100 --max-radius 5
named "eval detect: --min-radius above --max-radius" --min-radius $FV eval detect \
  --video "$TMP/v.avi" --labels "$TMP/none" --min-radius 100 --max-radius 5
named "detect: --dnn-width 33" --dnn-width $FV detect --video "$TMP/v.avi" --out "$TMP/d.csv" \
  --dnn-width 33
named "detect: --dnn-accept 2" --dnn-accept $FV detect --video "$TMP/v.avi" --out "$TMP/d.csv" \
  --dnn-accept 2
named "eval detect: --grow 9" --grow $FV eval detect --video "$TMP/v.avi" --labels "$TMP/none" \
  --grow 9
named "ball: --scan-bands above --full-scan-every" --scan-bands $FV ball --camera "$TMP/c1.yaml" \
  --video "$TMP/v.avi" --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --out "$TMP/b.csv" \
  --scan-bands 50
named "fuse: --max-wait 0" --max-wait $FV fuse --listen tcp://127.0.0.1:0 --camera "$TMP/c1.yaml" \
  --camera "$TMP/c2.yaml" --out "$TMP/f.csv" --max-wait 0
named "eval detect: --min-visible 2" --min-visible $FV eval detect --video "$TMP/v.avi" \
  --labels "$TMP/none" --min-visible 2
named "players: --input-width 33" --input-width $FV players --video "$TMP/v.avi" \
  --out "$TMP/t.csv" --input-width 33
named "trajectory: --predict-fraction nan" --predict-fraction $FV trajectory --in "$TMP/none.csv" \
  --out "$TMP/f.json" --predict-fraction nan
named "ball: --max-frames with --detections" --max-frames $FV ball --camera "$TMP/c1.yaml" \
  --detections "$TMP/d1.csv" --camera "$TMP/c2.yaml" --detections "$TMP/d2.csv" \
  --out "$TMP/b.csv" --max-frames 2
named "ball: --color with --detections" --color $FV ball --camera "$TMP/c1.yaml" \
  --detections "$TMP/d1.csv" --camera "$TMP/c2.yaml" --detections "$TMP/d2.csv" \
  --out "$TMP/b.csv" --colour yellow
named "calibrate import: --image-size with --toml" --image-size $FV calibrate import \
  --toml "$TMP/none.toml" --image-size 640x480 --out "$TMP/imp_size"
named "studio: --live port 99999" --live timeout 20 $FV studio --port 0 \
  --live tcp://127.0.0.1:99999
named "calibrate intrinsics: --k3 free with --model 4" --k3 $FV calibrate intrinsics \
  --images "$TMP/none" --cols 9 --rows 6 --square 0.025 --out "$TMP/ci.yaml" --model 4 --k3 free
named "calibrate multi: --tangential free --zero-tangent" --zero-tangent $FV calibrate multi \
  --board chessboard --cols 9 --rows 6 --square 0.025 --views a="$TMP/none" \
  --views b="$TMP/none2" --out "$TMP/multi_tz" --tangential free --zero-tangent
named "calibrate extrinsics: --image-size with --camera" --image-size $FV calibrate extrinsics \
  --camera "$TMP/c1.yaml" --image-size 640x480 --points "$TMP/none.csv" --out "$TMP/ce.yaml"
named "calibrate extrinsics: --image-size over the limit" --image-size $FV calibrate \
  extrinsics --image-size 100000x100000 --points "$TMP/none.csv" --out "$TMP/ce.yaml"
named "calibrate intrinsics: --marker over --square" --marker $FV calibrate intrinsics \
  --images "$TMP/none" --board charuco --cols 5 --rows 7 --square 0.04 --marker 0.05 \
  --out "$TMP/ci.yaml"
named "plan: --search-step too fine" --search-step $FV plan --camera "$TMP/sc/cam1.yaml" \
  --camera "$TMP/sc/cam2.yaml" --out "$TMP/plan_fine" --optimize --search-step 1e-6 --no-progress
named "synth: --seed -1" --seed $FV synth --preset kick --seed -1 --out "$TMP/syn_m1"
[ -e "$TMP/syn_m1" ] && { echo "FAIL synth: a refused run made --out"; fail=1; }
named "plan: --good-angle 120 40" --good-angle $FV plan --rig "$TMP/none.json" --out "$TMP/plan" \
  --good-angle 120 40
check "eval ball: NaN truth" nonzero $FV eval ball --truth "$TMP/nan.csv" --est "$TMP/nan.csv"
# An output that is one of the inputs (by name or through a link) is refused; the input stays.
printf 'not a video\n' > "$TMP/v.avi"
ln -s v.avi "$TMP/link.avi"
printf 'frame,x_m,y_m,z_m\n0,1,2,0.11\n' > "$TMP/t.csv"
printf '<dataset></dataset>\n' > "$TMP/p.xml"
same_file() {  # same_file NAME INPUT CMD...: non-zero exit, one line, INPUT unchanged
  local name="$1" input="$2"
  shift 2
  cp "$input" "$TMP/before"
  check "$name" nonzero "$@"
  grep -q "is the same file as" "$TMP/err" || { echo "FAIL $name: not the same-file error"; fail=1; }
  cmp -s "$input" "$TMP/before" || { echo "FAIL $name: input changed"; fail=1; }
}
same_file "detect: --out is --video" "$TMP/v.avi" $FV detect --video "$TMP/v.avi" --out "$TMP/v.avi"
same_file "detect: --out links to --video" "$TMP/v.avi" $FV detect --video "$TMP/v.avi" \
  --out "$TMP/link.avi"
same_file "ball: --out is --truth" "$TMP/t.csv" $FV ball --camera "$TMP/c1.yaml" \
  --video "$TMP/v.avi" --camera "$TMP/c2.yaml" --video "$TMP/v2.avi" --truth "$TMP/t.csv" \
  --out "$TMP/t.csv"
same_file "players: --out is --video" "$TMP/v.avi" $FV players --video "$TMP/v.avi" \
  --out "$TMP/v.avi"
same_file "trajectory: --out is --in" "$TMP/t.csv" $FV trajectory --in "$TMP/t.csv" \
  --out "$TMP/t.csv"
printf '{"earlier": true}\n' > "$TMP/o.json"
same_file "trajectory: --smoothed is --out" "$TMP/o.json" $FV trajectory --in "$TMP/t.csv" \
  --out "$TMP/o.json" --smoothed "$TMP/o.json"
same_file "stats: --out holds --tracks" "$TMP/t.csv" $FV stats --tracks "$TMP/t.csv" \
  --field fifa --out "$TMP/t.csv"
same_file "import-pets: --out is --xml" "$TMP/p.xml" $FV eval import-pets --xml "$TMP/p.xml" \
  --out "$TMP/p.xml"
same_file "color learn: --out is --video" "$TMP/v.avi" $FV color learn --video "$TMP/v.avi" \
  --roi 1,1,2,2 --out "$TMP/v.avi"
# Sizes that would exhaust memory or never finish are refused before anything is allocated.
check "synth: 16384 px wide" nonzero $FV synth --preset static --width 16384 --height 16384 \
  --out "$TMP/synth"
check "synth: over 16 Mpx" nonzero $FV synth --preset static --width 8192 --height 8192 \
  --out "$TMP/synth"
check "players: --input-width 32000" nonzero $FV players --video "$TMP/v.avi" \
  --input-width 32000 --out "$TMP/tracks.csv"
grep -q -- --input-width "$TMP/err" || { echo "FAIL players: error does not name --input-width"; fail=1; }
check "plan: --step 1e-4" nonzero $FV plan --field fifa --optimize --step 1e-4 --out "$TMP/plan"
grep -q -- "--step 0.0001" "$TMP/err" || { echo "FAIL plan: error does not name the step"; fail=1; }
printf 'frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n' > "$TMP/tracks.csv"
for f in 1 2 3; do echo "$f,1,0,0,10,20,1,$f,0," >> "$TMP/tracks.csv"; done
echo "2000000000,1,0,0,10,20,1,5,0," >> "$TMP/tracks.csv"
check "stats: --fps 1e-300" nonzero $FV stats --tracks "$TMP/tracks.csv" --field fifa \
  --fps 1e-300 --out "$TMP/stats"
check "stats: frame 2e9" nonzero $FV stats --tracks "$TMP/tracks.csv" --field fifa --fps 25 \
  --out "$TMP/stats"
grep -q "tracks.csv" "$TMP/err" || { echo "FAIL stats: error does not name the file"; fail=1; }
check "option error" nonzero $FV synth --frames 0 --out "$TMP/synth"
# Metrics refuse impossible inputs; options that cannot apply are errors (issue 18).
printf 'frame,x_m,y_m,z_m\n0,1,2,0.11\n1,1,2,0.11\n' > "$TMP/truth.csv"
printf 'frame,x_m,y_m,z_m\n5,1,2,0.11\n6,1,2,0.11\n' > "$TMP/est.csv"
check "eval ball: nothing matched" nonzero $FV eval ball --truth "$TMP/truth.csv" --est "$TMP/est.csv"
grep -q "nothing to compare" "$TMP/err" || { echo "FAIL eval ball: not the no-match error"; fail=1; }
printf 'frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n' > "$TMP/gt.csv"
for f in 1 2 3; do echo "$f,1,0,0,10,20,1,,," >> "$TMP/gt.csv"; done
cp "$TMP/gt.csv" "$TMP/dup.csv" && echo "2,1,0,0,10,20,1,,," >> "$TMP/dup.csv"
check "eval tracks: a duplicated row" nonzero $FV eval tracks --gt "$TMP/gt.csv" --est "$TMP/dup.csv"
grep -q "two boxes in frame 2" "$TMP/err" || { echo "FAIL eval tracks: not the duplicate"; fail=1; }
printf '%%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\ndistortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n' > "$TMP/intr.yaml"
check "eval tracks: --camera without a pose" nonzero $FV eval tracks --gt "$TMP/gt.csv" \
  --est "$TMP/gt.csv" --camera "$TMP/intr.yaml"
grep -q "intr.yaml: the camera has no pose" "$TMP/err" || { echo "FAIL eval tracks: pose"; fail=1; }
# A walker at 1.5 m/s for 4 s scored against itself: positions exact, the coach's numbers equal.
awk 'BEGIN { print "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s";
  for (f = 1; f <= 41; f++) printf "%d,1,%d,100,20,50,1,%.3f,2,%.1f\n", f, 100 + f, 0.15 * (f - 1), (f - 1) / 10 }' \
  > "$TMP/walker.csv"
check "eval tracks: positions and coach's numbers" 0 $FV eval tracks --gt "$TMP/walker.csv" \
  --est "$TMP/walker.csv"
grep -q "median 0.000 m" "$TMP/out" && grep -q "distance over everyone 6 m against the ground truth's 6 m (+0.0 %)" "$TMP/out" ||
  { echo "FAIL eval tracks: positions or coach's numbers"; cat "$TMP/out"; fail=1; }
echo "4,2,0,0,10,20,1,nan,0," >> "$TMP/gt.csv"
check "stats: NaN position" nonzero $FV stats --tracks "$TMP/gt.csv" --field fifa --out "$TMP/st"
grep -q "gt.csv:5" "$TMP/err" || { echo "FAIL stats: NaN row not named"; fail=1; }
check "trajectory: --line without --field" nonzero $FV trajectory --in "$TMP/truth.csv" \
  --out "$TMP/f.json" --line touch_top
check "players: --margin without --field" nonzero $FV players --video "$TMP/v.avi" \
  --out "$TMP/tracks.csv" --margin 2
check "players: --moving-camera with the motion detector" nonzero $FV players \
  --video "$TMP/v.avi" --out "$TMP/tracks.csv" --moving-camera --detector motion
grep -q "needs a still camera" "$TMP/err" || { echo "FAIL players: moving motion"; fail=1; }
check "detect: --field without a camera" nonzero $FV detect --video "$TMP/v.avi" --field fifa \
  --out "$TMP/det.csv"
grep -q "needs --camera" "$TMP/err" || { echo "FAIL detect: not the --field error"; fail=1; }
printf '{"name": "huge", "length_m": 1e308, "width_m": 1e308}\n' > "$TMP/huge.json"
check "field of 1e308 m" nonzero $FV field show "$TMP/huge.json"
check "plan: --map-width 20000" nonzero $FV plan --field fifa --optimize --map-width 20000 \
  --out "$TMP/plan"
check "plan: --iterations 2e9" nonzero $FV plan --field fifa --optimize --iterations 2000000000 \
  --out "$TMP/plan"
check "calibrate intrinsics: --out in a missing folder" nonzero $FV calibrate intrinsics \
  --images "$TMP" --cols 9 --rows 6 --square 0.025 --out "$TMP/missing/x.yaml"
grep -q "does not exist; create it" "$TMP/err" || { echo "FAIL intrinsics: not the folder error"; fail=1; }
check "calibrate compare: one --rig" nonzero $FV calibrate compare --rig "$TMP"
# Issue 18's leftovers: outputs, option ranges, numbers in files, library noise.
"$FV" synth --preset kick --frames 1 --width 320 --height 240 --format png --out "$TMP/sc" \
  --quiet >/dev/null 2>&1 || { echo "FAIL synth of the fixture"; fail=1; }
mknod "$TMP/dev" c 1 3 2>/dev/null || mkfifo "$TMP/dev"
printf 'u,v,name\n160,120,centre_spot\n160,20,halfway_top\n160,220,halfway_bottom\n10,220,corner_left_bottom\n' \
  >"$TMP/pts.csv"
printf '<dataset><frame number="0"><objectlist><object id="1"><box h="60" w="20" xc="20" yc="80"/></object></objectlist></frame></dataset>\n' \
  >"$TMP/pets.xml"
device_out() {  # device_out NAME CMD...: refused, and the device is still one
  local name="$1"
  shift
  check "$name" nonzero "$@"
  [ -c "$TMP/dev" ] || [ -p "$TMP/dev" ] || { echo "FAIL $name: the device was replaced"; fail=1; }
  grep -q "not a regular file" "$TMP/err" || { echo "FAIL $name: not the device error"; fail=1; }
}
device_out "calibrate extrinsics: --out a device" $FV calibrate extrinsics --field robocup-msl \
  --camera "$TMP/sc/cam1.yaml" --points "$TMP/pts.csv" --out "$TMP/dev"
device_out "calibrate refine: --out a device" $FV calibrate refine --field robocup-msl \
  --camera "$TMP/sc/cam1.yaml" --image "$TMP/sc/cam1/00000.png" --out "$TMP/dev"
device_out "calibrate intrinsics: --out a device (before the board search)" $FV calibrate \
  intrinsics --images "$TMP/sc/cam1" --cols 9 --rows 6 --square 0.025 --out "$TMP/dev" --quiet
device_out "eval import-pets: --out a device" $FV eval import-pets --xml "$TMP/pets.xml" \
  --out "$TMP/dev"
check "calibrate intrinsics: --outlier-factor 1e300 (before the board search)" nonzero $FV \
  calibrate intrinsics --images "$TMP/sc/cam1" --cols 9 --rows 6 --square 0.025 \
  --outlier-factor 1e300 --out "$TMP/i.yaml" --quiet
grep -q -- "--outlier-factor" "$TMP/err" || { echo "FAIL intrinsics: option not named"; fail=1; }
head -c 2000 "$TMP/sc/cam1/00000.png" >"$TMP/cut.png"
check "calibrate check: a damaged PNG (no libpng line)" nonzero $FV calibrate check \
  --field robocup-msl --camera "$TMP/sc/cam1.yaml" --image "$TMP/cut.png" --out "$TMP/chk.png"
{ printf 'P5 320 240 255\n'; head -c 76800 /dev/zero; } >"$TMP/black.pgm"
cp "$TMP/sc/cam1.yaml" "$TMP/kept.yaml"
check "calibrate refine: a frame without lines" nonzero $FV calibrate refine --field robocup-msl \
  --camera "$TMP/sc/cam1.yaml" --image "$TMP/black.pgm" --out "$TMP/kept.yaml"
cmp -s "$TMP/sc/cam1.yaml" "$TMP/kept.yaml" || { echo "FAIL refine: wrote without lines"; fail=1; }
: >"$TMP/nodet.txt"
check "players: --detections empty" nonzero $FV players --video "$TMP/sc/cam1/%05d.png" \
  --detections "$TMP/nodet.txt" --out "$TMP/pl.csv" --no-progress
printf '{"cameras": [{"name": "c1", "position": [0, -8, 4], "look_at": [0, 0, 0], "image_width": 640, "image_height": 480, "hfov_deg": 70}]}\n' \
  >"$TMP/rig.json"
check "plan: --error-weight 1e300" nonzero $FV plan --rig "$TMP/rig.json" --error-weight 1e300 \
  --out "$TMP/pl" --no-progress
grep -q -- "--error-weight" "$TMP/err" || { echo "FAIL plan: option not named"; fail=1; }
check "plan: --hfov without --optimize" nonzero $FV plan --rig "$TMP/rig.json" --hfov 50 \
  --out "$TMP/pl" --no-progress
printf 'frame,x_m,y_m,z_m\n0,1,2,0.11\n1,1,1e300,0.11\n' >"$TMP/huge.csv"
check "eval ball: 1e300 in a file" nonzero $FV eval ball --truth "$TMP/truth.csv" \
  --est "$TMP/huge.csv"
grep -q "huge.csv:3" "$TMP/err" || { echo "FAIL eval ball: file and line not named"; fail=1; }
printf 'frame,x_m,y_m,z_m\n0,1,2,0.11\n2000000000,1,2,0.11\n' >"$TMP/far.csv"
check "eval ball: frame 2e9 in a file" nonzero $FV eval ball --truth "$TMP/far.csv" \
  --est "$TMP/truth.csv"
grep -q "far.csv:3" "$TMP/err" || { echo "FAIL eval ball: file and line not named"; fail=1; }
cp "$TMP/tracks.csv" "$TMP/far_tracks.csv"
head -4 "$TMP/tracks.csv" >"$TMP/gt3.csv"
check "eval tracks: frame 2e9 in a file" nonzero $FV eval tracks --gt "$TMP/gt3.csv" \
  --est "$TMP/far_tracks.csv"
grep -q "far_tracks.csv:5" "$TMP/err" || { echo "FAIL eval tracks: line not named"; fail=1; }
head -4 "$TMP/tracks.csv" >"$TMP/dup_tracks.csv" && sed -n 3p "$TMP/tracks.csv" >>"$TMP/dup_tracks.csv"
check "stats: a duplicated row" nonzero $FV stats --tracks "$TMP/dup_tracks.csv" --field fifa \
  --out "$TMP/st2" --no-video
grep -q "two rows in frame 2" "$TMP/err" || { echo "FAIL stats: not the duplicate"; fail=1; }
check "stats: --smooth 1e300" nonzero $FV stats --tracks "$TMP/gt3.csv" --field fifa \
  --smooth 1e300 --out "$TMP/st3" --no-video
grep -q -- "--smooth" "$TMP/err" || { echo "FAIL stats: option not named"; fail=1; }
check "fuse: --tolerance 1e300 (hung)" nonzero timeout 20 $FV fuse --listen tcp://127.0.0.1:0 \
  --camera "$TMP/sc/cam1.yaml" --camera "$TMP/sc/cam2.yaml" --out "$TMP/f.csv" --tolerance 1e300 \
  --no-progress
# A fusion node's log (stderr not a terminal) gets no progress redraws.
timeout -s INT 2 $FV fuse --listen tcp://127.0.0.1:0 --camera "$TMP/sc/cam1.yaml" \
  --camera "$TMP/sc/cam2.yaml" --out "$TMP/f.csv" >/dev/null 2>"$TMP/fuse_log"
if grep -q $'\r' "$TMP/fuse_log"; then echo "FAIL fuse: progress in a log"; fail=1; else
  echo "ok   fuse: quiet in a log"; fi
check "fuse: --listen not this machine's" nonzero timeout 20 $FV fuse \
  --listen tcp://192.0.2.1:5555 --camera "$TMP/sc/cam1.yaml" --camera "$TMP/sc/cam2.yaml" \
  --out "$TMP/f.csv" --no-progress
grep -q "tcp://\*:PORT" "$TMP/err" || { echo "FAIL fuse: no advice for a foreign address"; fail=1; }
check "studio: --assets a missing folder" nonzero timeout 20 $FV studio --assets "$TMP/none" \
  --port 0
check "node: --start-at 1e300" nonzero $FV node --camera "$TMP/sc/cam1.yaml" \
  --video "$TMP/sc/cam1/%05d.png" --connect tcp://127.0.0.1:1 --connect-wait 0.2 \
  --start-at 1e300 --no-progress
# GStreamer's own CRITICAL lines (a pipeline OpenCV cannot end in an appsink) stay quiet.
check "node: a GStreamer pipeline without a sink for OpenCV" nonzero timeout 30 $FV node \
  --camera "$TMP/sc/cam1.yaml" --video 'gst:videotestsrc num-buffers=3 ! fakesink' \
  --connect tcp://127.0.0.1:1 --connect-wait 0.2 --no-progress
# ball: a video given twice under two names, a truncated video and a bad --timestamps file
# (issue 18): one line naming the input, the existing --out unchanged, no temporary file left.
"$FV" synth --preset kick --frames 6 --width 320 --height 240 --out "$TMP/bv" --quiet \
  >/dev/null 2>&1 || { echo "FAIL synth of the ball fixture"; fail=1; }
B2=(--camera "$TMP/bv/cam1.yaml" --camera "$TMP/bv/cam2.yaml" --no-progress)
check "ball: one video as v.avi and ./v.avi" nonzero $FV ball "${B2[@]}" --video "$TMP/bv/cam1.avi" \
  --video "$TMP/bv/./cam1.avi" --out "$TMP/bv/b.csv"
grep -q "given twice" "$TMP/err" || { echo "FAIL ball: the alias of a video is not refused"; fail=1; }
printf 'existing output\n' >"$TMP/bv/old.csv"
head -c 40000 "$TMP/bv/cam1.avi" >"$TMP/bv/cut.avi"
check "ball: a truncated video" nonzero $FV ball "${B2[@]}" --video "$TMP/bv/cut.avi" \
  --video "$TMP/bv/cam2.avi" --out "$TMP/bv/old.csv"
grep -q "cut.avi" "$TMP/err" || { echo "FAIL ball: truncated video not named"; fail=1; }
ls "$TMP/bv" | grep -q part && { echo "FAIL ball: a temporary file is left"; fail=1; }
printf 'frame,time_s\n0,0\n1,0.0167\n2,0.01\n3,0.05\n4,0.0667\n5,0.0833\n' >"$TMP/bv/ts.csv"
check "ball: --timestamps going backwards" nonzero $FV ball "${B2[@]}" --video "$TMP/bv/cam1.avi" \
  --video "$TMP/bv/cam2.avi" --timestamps "$TMP/bv/ts.csv" --timestamps "$TMP/bv/ts.csv" \
  --out "$TMP/bv/old.csv"
grep -q "ts.csv:4" "$TMP/err" || { echo "FAIL ball: timestamps line not named"; fail=1; }
[ "$(cat "$TMP/bv/old.csv")" = "existing output" ] || { echo "FAIL ball: --out changed"; fail=1; }
# calibrate check on a frame without a field line: an error, not "line error 0.0 mm".
{ printf 'P6\n320 240\n255\n'; head -c 230400 /dev/zero; } >"$TMP/black.ppm"
check "calibrate check: no line in view" nonzero $FV calibrate check --field robocup-msl \
  --camera "$TMP/bv/cam1.yaml" --image "$TMP/black.ppm" --out "$TMP/bv/chk.png"
grep -q "sees no line" "$TMP/err" || { echo "FAIL calibrate check: not the no-line error"; fail=1; }
# calibrate import: camera names from the file never leave --out; two of one name are refused.
toml_cam() {  # toml_cam SECTION NAME
  printf '[%s]\nname = "%s"\nsize = [ 640.0, 480.0,]\n' "$1" "$2"
  printf 'matrix = [ [ 500.0, 0.0, 320.0,], [ 0.0, 500.0, 240.0,], [ 0.0, 0.0, 1.0,],]\n'
  printf 'distortions = [ 0.0, 0.0, 0.0, 0.0,]\nrotation = [ 0.0, 0.0, 0.0,]\n'
  printf 'translation = [ 0.0, 0.0, 2000.0,]\n\n'
}
mkdir -p "$TMP/imp/deep"
{ toml_cam cam_0 ../../escaped; toml_cam cam_1 B; } >"$TMP/imp/calibration.toml"
FV_ABS="$(cd "$(dirname "$FV")" && pwd)/$(basename "$FV")"
(cd "$TMP/imp/deep" && check "calibrate import: a name with ../" 0 "$FV_ABS" calibrate import \
  --toml ../calibration.toml --out rig)
[ -e "$TMP/escaped.yaml" ] || [ -e "$TMP/imp/escaped.yaml" ] &&
  { echo "FAIL calibrate import: a camera file written outside --out"; fail=1; }
[ "$(ls "$TMP/imp/deep/rig" | wc -l)" = 2 ] || { echo "FAIL calibrate import: not 2 files"; fail=1; }
{ toml_cam cam_0 A; toml_cam cam_1 A; } >"$TMP/imp/twice.toml"
check "calibrate import: two cameras of one name" nonzero $FV calibrate import \
  --toml "$TMP/imp/twice.toml" --out "$TMP/imp/twice"
grep -q "two cameras named 'A'" "$TMP/err" || { echo "FAIL calibrate import: not refused"; fail=1; }
[ -e "$TMP/imp/twice" ] && { echo "FAIL calibrate import: a refused run made --out"; fail=1; }
# A drawn video's name must say its container: refused before any work, naming the option.
check "players --draw an image name" nonzero $FV players --video "$TMP/v.avi" --out "$TMP/pt.csv" \
  --draw "$TMP/out.jpg"
grep -q -- "--draw '.*out.jpg': a video's name ends in .mp4, .avi or .mkv" "$TMP/err" ||
  { echo "FAIL players --draw out.jpg: not refused by its name"; fail=1; }
check "calibrate import: --units with a Qualisys file" nonzero $FV calibrate import \
  --qualisys "$TMP/imp/none.qca.txt" --units cm --out "$TMP/imp/q"
grep -q "units applies to --toml" "$TMP/err" || { echo "FAIL calibrate import: --units taken"; fail=1; }
# A video with damaged data (bytes zeroed in the middle): FFmpeg conceals it, the run says so.
"$FV" synth --preset kick --frames 30 --width 320 --height 240 --out "$TMP/dmg" --quiet \
  >/dev/null 2>&1
"$FV" detect --video "$TMP/dmg/cam1.avi" --out "$TMP/dmg/d.csv" --draw "$TMP/dmg/v.mp4" \
  --no-progress >/dev/null 2>&1
if [ -s "$TMP/dmg/v.mp4" ]; then  # only where OpenCV's FFmpeg encodes H.264
  size=$(stat -c %s "$TMP/dmg/v.mp4")
  for k in 2 3 4 5; do
    dd if=/dev/zero of="$TMP/dmg/v.mp4" bs=1 seek=$((size * k / 7)) count=300 conv=notrunc \
      2>/dev/null
  done
  check "detect: a damaged H.264 video" 0 $FV detect --video "$TMP/dmg/v.mp4" \
    --out "$TMP/dmg/d2.csv" --no-progress
  grep -q "damaged data" "$TMP/err" || { echo "FAIL detect: damaged video not reported"; fail=1; }
  check "detect: the undamaged video" 0 $FV detect --video "$TMP/dmg/cam1.avi" \
    --out "$TMP/dmg/d3.csv" --no-progress
  grep -q "damaged data" "$TMP/err" && { echo "FAIL detect: an intact video reported"; fail=1; }
fi
# No output replaces an input, and a rig folder never mixes two calibrations.
same_file "eval detect: --out a label file" "$TMP/dimgs/a.txt" $FV eval detect \
  --video "$TMP/dimgs" --out "$TMP/dimgs/a.txt" --detector colour --no-progress
check "eval detect: --candidates is --out" nonzero $FV eval detect --video "$TMP/dimgs" \
  --out "$TMP/ec.csv" --candidates "$TMP/ec.csv" --detector colour --no-progress
same_file "calibrate intrinsics: --out a board image" "$TMP/sc/cam1/00000.png" $FV calibrate \
  intrinsics --images "$TMP/sc/cam1" --cols 9 --rows 6 --square 0.025 \
  --out "$TMP/sc/cam1/00000.png" --quiet
same_file "calibrate export: --toml a camera file" "$TMP/imp/deep/rig/B.yaml" $FV calibrate export \
  --rig "$TMP/imp/deep/rig" --toml "$TMP/imp/deep/rig/B.yaml"
mkdir -p "$TMP/rigin" && cp "$TMP/sc/cam1.yaml" "$TMP/rigin/cam1.yaml"
printf 'u,v,name,x,y,z\n160,120,p1,0,0,0\n' >"$TMP/rigin/p.csv"
same_file "calibrate rig: --out-dir the cameras' folder" "$TMP/rigin/cam1.yaml" $FV calibrate rig \
  --camera "$TMP/rigin/cam1.yaml" --points "$TMP/rigin/p.csv" --out-dir "$TMP/rigin"
same_file "calibrate multi: --out the folder of --intrinsics" "$TMP/rigin/cam1.yaml" $FV calibrate \
  multi --cols 9 --rows 6 --square 0.025 --views "cam1=$TMP/sc/cam1" \
  --views "cam2=$TMP/sc/cam2" --intrinsics "cam1=$TMP/rigin/cam1.yaml" --out "$TMP/rigin" --quiet
# A rig placed in its own folder keeps its file names (first.yml holds the camera cam1).
mkdir -p "$TMP/inplace" && cp "$TMP/sc/cam1.yaml" "$TMP/inplace/first.yml"
check "calibrate extrinsics: --rig placed in its own folder" 0 $FV calibrate extrinsics \
  --rig "$TMP/inplace" --points "cam1=$TMP/pts.csv" --field robocup-msl --out "$TMP/inplace"
[ "$(ls "$TMP/inplace")" = "first.yml" ] || { echo "FAIL extrinsics --rig: files renamed"; fail=1; }
check "calibrate import: --out holds another rig's camera" nonzero $FV calibrate import \
  --toml "$TMP/imp/calibration.toml" --out "$TMP/rigin"
grep -q "already holds the camera file 'cam1.yaml'" "$TMP/err" ||
  { echo "FAIL calibrate import: a folder of other cameras taken"; fail=1; }
# tracks edit: a run without teams or names removes an earlier run's teams file beside --out.
printf 'frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n1,1,10,10,5,10,0.9,0,0,0\n1,2,30,10,5,10,0.9,1,0,0\n' \
  >"$TMP/tr.csv"
echo '[{"team": {"1": 0}}]' >"$TMP/team.json" && echo '[{"rename": {"2": 7}}]' >"$TMP/ren.json"
check "tracks edit: a team" 0 $FV tracks edit --tracks "$TMP/tr.csv" --edits "$TMP/team.json" \
  --out "$TMP/ed.csv"
[ -s "$TMP/ed.csv.teams.csv" ] || { echo "FAIL tracks edit: no teams file"; fail=1; }
check "tracks edit: no team" 0 $FV tracks edit --tracks "$TMP/tr.csv" --edits "$TMP/ren.json" \
  --out "$TMP/ed.csv"
[ -e "$TMP/ed.csv.teams.csv" ] && { echo "FAIL tracks edit: an earlier run's teams kept"; fail=1; }
printf 'frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n5,1,1000,900,5,10,0.9,0,0,0\n' \
  >"$TMP/tr_far.csv"
check "tracks draw: tracks of another video" nonzero $FV tracks draw \
  --tracks "$TMP/tr_far.csv" --video "$TMP/sc/cam1/%05d.png" --out "$TMP/trd.avi"
grep -q "tracks of another video?); nothing written" "$TMP/err" ||
  { echo "FAIL tracks draw: another video not said"; fail=1; }
[ -e "$TMP/trd.avi" ] && { echo "FAIL tracks draw: wrote tracks of another video"; fail=1; }
check "tracks draw: tracks on part of the video" 0 $FV tracks draw --tracks "$TMP/tr.csv" \
  --video "$TMP/bv/cam1.avi" --out "$TMP/trp.avi"
grep -q "the tracks cover frames 1-1 of the 6 drawn" "$TMP/out" ||
  { echo "FAIL tracks draw: the covered frames not said"; fail=1; }
check "tracks draw: --field without a camera" nonzero $FV tracks draw --tracks "$TMP/tr.csv" \
  --video "$TMP/bv/cam1.avi" --field robocup-msl --out "$TMP/trf.avi"
# A moving camera's motion goes beside its TRACKS.csv; tracks draw reads it; a still run removes it.
check "players: --moving-camera writes its motion" 0 $FV players --camera "$TMP/bv/cam1.yaml" \
  --video "$TMP/bv/cam1.avi" --out "$TMP/mv.csv" --moving-camera --no-progress
[ -s "$TMP/mv.csv.motion.json" ] || { echo "FAIL players: no motion file"; fail=1; }
check "players: --moving-camera on a field with lines" 0 $FV players --camera "$TMP/bv/cam1.yaml" \
  --video "$TMP/bv/cam1.avi" --field robocup-msl --out "$TMP/mvl.csv" --moving-camera --no-progress
grep -q "field lines: " "$TMP/out" || { echo "FAIL players: the field lines not used"; fail=1; }
check "players: --no-line-anchor" 0 $FV players --camera "$TMP/bv/cam1.yaml" \
  --video "$TMP/bv/cam1.avi" --field robocup-msl --out "$TMP/mvl.csv" --moving-camera \
  --no-line-anchor --no-progress
grep -q "field lines: " "$TMP/out" && { echo "FAIL players: --no-line-anchor ignored"; fail=1; }
check "players: --moving-centre" 0 $FV players --camera "$TMP/bv/cam1.yaml" \
  --video "$TMP/bv/cam1.avi" --field robocup-msl --out "$TMP/mvl.csv" --moving-camera \
  --moving-centre --no-progress
grep -q "features on the ground alone" "$TMP/out" ||
  { echo "FAIL players: --moving-centre not on the ground"; fail=1; }
check "players: --moving-centre without a field" nonzero $FV players \
  --camera "$TMP/bv/cam1.yaml" --video "$TMP/bv/cam1.avi" --out "$TMP/mvl.csv" --moving-camera \
  --moving-centre
grep -q "needs a posed camera file and a field" "$TMP/err" ||
  { echo "FAIL players: --moving-centre without a field"; fail=1; }
check "players: --canvas-margin without --moving-camera" nonzero $FV players \
  --camera "$TMP/bv/cam1.yaml" --video "$TMP/bv/cam1.avi" --out "$TMP/mvl.csv" --canvas-margin 2
grep -q "requires --moving-camera" "$TMP/err" || { echo "FAIL players: margin alone"; fail=1; }
check "players: --no-line-anchor without --moving-camera" nonzero $FV players \
  --camera "$TMP/bv/cam1.yaml" --video "$TMP/bv/cam1.avi" --out "$TMP/mvl.csv" --no-line-anchor
# (the scene has no people: its motion goes with a TRACKS.csv of one row)
cp "$TMP/tr.csv" "$TMP/trm.csv" && cp "$TMP/mv.csv.motion.json" "$TMP/trm.csv.motion.json"
check "tracks draw: a moving camera's motion" 0 $FV tracks draw --tracks "$TMP/trm.csv" \
  --video "$TMP/bv/cam1.avi" --camera "$TMP/bv/cam1.yaml" --field robocup-msl --out "$TMP/mvd.avi"
grep -q "camera motion from .*trm.csv.motion.json (6 frames)" "$TMP/out" ||
  { echo "FAIL tracks draw: motion file not read"; fail=1; }
check "eval tracks: a moving camera's ground truth" 0 $FV eval tracks --gt "$TMP/trm.csv" \
  --est "$TMP/trm.csv" --camera "$TMP/bv/cam1.yaml"
grep -q "ground truth placed through the camera's motion" "$TMP/out" ||
  { echo "FAIL eval tracks: motion file not used"; fail=1; }
check "tracks edit: the motion goes with the tracks" 0 $FV tracks edit --tracks "$TMP/trm.csv" \
  --edits "$TMP/ren.json" --out "$TMP/trm_ed.csv"
cmp -s "$TMP/trm.csv.motion.json" "$TMP/trm_ed.csv.motion.json" ||
  { echo "FAIL tracks edit: motion file not carried"; fail=1; }
echo '{"format": "fieldvision camera motion 1"' >"$TMP/trm.csv.motion.json"
check "tracks draw: a broken motion file" nonzero $FV tracks draw --tracks "$TMP/trm.csv" \
  --video "$TMP/bv/cam1.avi" --out "$TMP/mvd.avi"
grep -q "trm.csv.motion.json" "$TMP/err" || { echo "FAIL tracks draw: motion file not named"; fail=1; }
check "players: a still camera removes the motion" 0 $FV players --camera "$TMP/bv/cam1.yaml" \
  --video "$TMP/bv/cam1.avi" --out "$TMP/mv.csv" --no-progress
[ -e "$TMP/mv.csv.motion.json" ] && { echo "FAIL players: an earlier motion file kept"; fail=1; }
# Progress: a line redrawn on a terminal; nothing in a log unless asked for (the studio's jobs).
"$FV" synth --preset kick --frames 3 --width 160 --height 120 --out "$TMP/prog" >/dev/null \
  2>"$TMP/prog.err"
grep -q "elapsed" "$TMP/prog.err" && { echo "FAIL synth: progress lines in a log"; fail=1; }
FV_PROGRESS=lines "$FV" synth --preset kick --frames 3 --width 160 --height 120 \
  --out "$TMP/prog2" >/dev/null 2>"$TMP/prog.err"
grep -q "elapsed" "$TMP/prog.err" || { echo "FAIL synth: FV_PROGRESS=lines gave no line"; fail=1; }
# A stop asked by a signal says so, on a line of its own (no blank line before it in a log).
"$FV" fuse --listen "tcp://127.0.0.1:*" --camera "$TMP/sc/cam1.yaml" \
  --camera "$TMP/sc/cam2.yaml" --out "$TMP/fuse_sig.csv" >/dev/null 2>"$TMP/fuse_sig.err" &
fuse_pid=$!
for _ in $(seq 100); do grep -q "listening" "$TMP/fuse_sig.err" 2>/dev/null && break; sleep 0.1; done
kill -TERM "$fuse_pid"
wait "$fuse_pid"
head -1 "$TMP/fuse_sig.err" | grep -q "^stopping (again to quit at once" || {
  echo "FAIL fuse: the stop's message is not the first line:"; cat "$TMP/fuse_sig.err"; fail=1; }
exit $fail
