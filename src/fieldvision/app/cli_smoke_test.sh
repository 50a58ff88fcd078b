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
         "color learn" "calibrate check" "calibrate rig" "eval tracks"; do
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
check "eval ball: NaN truth" nonzero $FV eval ball --truth "$TMP/nan.csv" --est "$TMP/nan.csv"
exit $fail
