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
done
check "field show" 0 $FV field show robocup-msl
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
check "detect: --ball-diameter 1e300" nonzero $FV detect --video "$TMP/v.avi" --out "$TMP/d.csv" \
  --ball-diameter 1e300
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
  grep -q "is the input" "$TMP/err" || { echo "FAIL $name: not the same-file error"; fail=1; }
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
grep -q input_width "$TMP/err" || { echo "FAIL players: error does not name input_width"; fail=1; }
check "plan: --step 1e-4" nonzero $FV plan --field fifa --optimize --step 1e-4 --out "$TMP/plan"
grep -q "grid step" "$TMP/err" || { echo "FAIL plan: error does not name the step"; fail=1; }
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
echo "4,2,0,0,10,20,1,nan,0," >> "$TMP/gt.csv"
check "stats: NaN position" nonzero $FV stats --tracks "$TMP/gt.csv" --field fifa --out "$TMP/st"
grep -q "gt.csv:5" "$TMP/err" || { echo "FAIL stats: NaN row not named"; fail=1; }
check "trajectory: --line without --field" nonzero $FV trajectory --in "$TMP/truth.csv" \
  --out "$TMP/f.json" --line touch_top
check "players: --margin without --field" nonzero $FV players --video "$TMP/v.avi" \
  --out "$TMP/tracks.csv" --margin 2
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
exit $fail
