#!/usr/bin/env bash
# Bad-input sweep over every subcommand (issue 18): each case runs `fieldvision` on one bad input
# (missing, empty, binary, truncated or inconsistent file; NaN/Inf/huge numbers in cameras, CSVs
# and JSON; an output that is an input, a link to one, a folder or a device; bad option values)
# while every other input is good, and checks that it
#   - exits non-zero, not by a signal, in under 30 s (timeout),
#   - prints exactly one line on stderr, naming the bad input (file name or option),
#   - leaves every input and existing output unchanged and no new file behind (hashes before and
#     after over the whole working folder),
#   - stays under 2 GB of memory (maximum RSS from /usr/bin/time).
# Usage: sweep_bad_inputs.sh FIELDVISION WORKDIR [--quick] [--only REGEX] [--shard I/N] [--list]
#   --quick  one or two cases per input kind and command (CTest, a few seconds)
#   --only   cases whose name matches REGEX
#   --shard  every N-th case from the I-th (0-based), to run N sweeps side by side
# Prints one line per failed case (and with -v every case) and a summary; exit 1 if any failed.
set -u
FV="$(realpath "$1")"
W="$2"
shift 2
QUICK=0 ONLY="" LIST=0 VERBOSE=0 SHARD_I=0 SHARD_N=1 index=0
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) QUICK=1 ;;
    --only) ONLY="$2"; shift ;;
    --list) LIST=1 ;;
    --shard) SHARD_I="${2%/*}"; SHARD_N="${2#*/}"; shift ;;
    -v) VERBOSE=1 ;;
    *) echo "sweep: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
TIME_LIMIT_S=${SWEEP_TIME_LIMIT_S:-30}
ASAN=0
grep -qa __asan_init "$FV" && ASAN=1
MEM_LIMIT_KB=${SWEEP_MEM_LIMIT_KB:-2097152}
rm -rf "$W" && mkdir -p "$W"
W="$(realpath "$W")"
F="$W/fx"     # good inputs
B="$W/bad"    # bad inputs
O="$W/out"    # existing outputs (must survive a failed run) and new outputs (must not appear)
S="$W/state"  # the sweep's own files, not checked
mkdir -p "$F" "$B" "$O" "$S"

# ---- good inputs: a small synthetic kick scene (4 cameras, 6 frames, 320x240)
"$FV" synth --preset kick --out "$F" --frames 6 --width 320 --height 240 --quiet >/dev/null 2>&1 ||
  { echo "sweep: synth failed"; exit 1; }
rm -f "$F/contact_sheet.png"
"$FV" synth --preset kick --out "$W/png" --frames 3 --width 320 --height 240 --format png \
  --quiet >/dev/null 2>&1 || { echo "sweep: synth png failed"; exit 1; }
mkdir -p "$F/frames" && cp "$W"/png/cam1/*.png "$F/frames/" 2>/dev/null ||
  cp "$(find "$W/png" -name '*.png' | sort | head -1)" "$F/frames/00000.png"
FRAME="$(find "$F/frames" -name '*.png' | sort | head -1)"
# Ball labels for eval detect: a YOLO file per frame (folder of images) and a CSV (video).
mkdir -p "$F/labels"
for p in "$F"/frames/*.png; do printf '0 0.5 0.5 0.1 0.1\n' >"$F/labels/$(basename "$p" .png).txt"; done
printf 'frame,x,y,w,h\n0,150,110,20,20\n1,150,110,20,20\n' >"$F/labels.csv"
rm -rf "$W/png"
cp "$F/truth.csv" "$F/BALL.csv"
# Ball detections of cam1/cam2 from truth_2d (frame,time_s,u,v,radius_px,score).
for c in cam1 cam2; do
  awk -F, -v c=$c 'NR==1{print "frame,time_s,u,v,radius_px,score"; next}
    $2==c {printf "%d,%.6f,%s,%s,%s,1\n", $1, $1/60.0, $3, $4, $5}' "$F/truth_2d.csv" \
    >"$F/det_$c.csv"
done
printf 'frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n' >"$F/TRACKS.csv"
# Two players, 60 frames at 25 fps (stats needs tracks of a second or more).
awk 'BEGIN { for (f = 1; f <= 60; f++) {
  printf "%d,1,%d,50,20,60,0.9,%.2f,1.0,%.2f\n", f, 10 + f, 0.1 * f, (f - 1) / 25
  printf "%d,2,%d,60,20,60,0.8,%.2f,2.0,%.2f\n", f, 100 + f, -0.1 * f, (f - 1) / 25 } }' \
  >>"$F/TRACKS.csv"
printf '1,-1,10,50,20,60,0.9\n2,-1,11,50,20,60,0.9\n' >"$F/det.txt"
printf '[{"name": "box", "polygon": [[0, 0], [5, 0], [5, 3]]}]\n' >"$F/zones.json"
printf '[{"rename": {"1": 10}}]\n' >"$F/edits.json"
printf 'id,team,name\n1,A,Ann\n2,B,Bob\n' >"$F/roster.csv"
"$FV" field show robocup-msl --json >"$F/field.json" 2>/dev/null
printf '{"name": "r", "defaults": {"image_width": 640, "image_height": 480, "hfov_deg": 70}, "cameras": [{"name": "c1", "position": [0, -8, 4], "look_at": [0, 0, 0]}, {"name": "c2", "position": [6, -8, 4], "look_at": [0, 0, 0]}]}\n' >"$F/rig.json"
printf '{"mounts": [{"point": [0, -8, 4]}, {"line": [[-6, -8, 4], [6, -8, 4]]}]}\n' >"$F/mounts.json"
# Field points of cam1: u,v,x,y,z from the field's keypoints projected by the synth camera are not
# at hand; named points on the field (u,v,name) with made-up pixels serve as a readable file.
printf 'u,v,name\n160,120,centre_spot\n160,20,halfway_top\n160,220,halfway_bottom\n10,220,corner_left_bottom\n' \
  >"$F/points.csv"
printf '<?xml version="1.0"?>\n<dataset name="x">\n<frame number="0"><objectlist><object id="1"><box h="60" w="20" xc="20" yc="80"/></object></objectlist></frame>\n</dataset>\n' >"$F/pets.xml"
printf '{"name": "ball", "classes": []}\n' >"$F/colour_bad_shape.json"

# ---- existing outputs: each must be unchanged after a failed run
for e in csv json png yaml avi mp4 txt; do printf 'existing output\n' >"$O/old.$e"; done
mkdir -p "$O/olddir" && printf 'existing output\n' >"$O/olddir/keep.txt"
# A device of the sweep's own as an output (never a system one: a writer that renames over its
# output would replace /dev/null for the whole machine); a FIFO where mknod is not allowed.
mknod "$O/device" c 1 3 2>/dev/null || mkfifo "$O/device"
DEV="$O/device"
# Links to every good input, for outputs given as a link to an input.
for f in "$F"/* "$FRAME"; do [ -f "$f" ] && ln -sf "$f" "$O/link_$(basename "$f")"; done

# ---- bad inputs
mkbad() { printf '%b' "$2" >"$B/$1"; }
: >"$B/empty.yaml"; : >"$B/empty.avi"; : >"$B/empty.csv"; : >"$B/empty.json"; : >"$B/empty.xml"
: >"$B/empty.png"; : >"$B/empty.txt"
head -c 3000 /dev/urandom >"$B/binary.yaml"
cp "$B/binary.yaml" "$B/binary.avi"; cp "$B/binary.yaml" "$B/binary.csv"
cp "$B/binary.yaml" "$B/binary.json"; cp "$B/binary.yaml" "$B/binary.png"
cp "$B/binary.yaml" "$B/binary.xml"; cp "$B/binary.yaml" "$B/binary.txt"
mkdir -p "$B/folder.yaml" "$B/folder.avi" "$B/folder.csv" "$B/folder.json" "$B/noimages"
head -c 40000 "$F/cam1.avi" >"$B/truncated.avi"
head -c 400 "$F/cam1.yaml" >"$B/truncated.yaml"
head -c 300 "$F/field.json" >"$B/truncated.json"
head -c 2000 "$FRAME" >"$B/truncated.png"
printf 'not a video\n' >"$B/text.avi"
# Cameras: one bad number at a time.
cam() {  # cam NAME SED_EXPR
  sed -e "$2" "$F/cam1.yaml" >"$B/$1.yaml"
}
cam nan_focal 's/data: \[ 2\.08[0-9e+.]*,/data: [ .Nan,/'
cam inf_focal 's/data: \[ 2\.08[0-9e+.]*,/data: [ .Inf,/'
cam neg_focal 's/data: \[ 2\.08[0-9e+.]*,/data: [ -2.0e+02,/'
cam zero_focal 's/data: \[ 2\.08[0-9e+.]*,/data: [ 0.,/'
cam huge_focal 's/data: \[ 2\.08[0-9e+.]*,/data: [ 1.0e+300,/'
cam huge_width 's/image_width: 320/image_width: 2000000000/'
cam neg_height 's/image_height: 240/image_height: -240/'
cam zero_width 's/image_width: 320/image_width: 0/'
cam wrong_size 's/image_width: 320/image_width: 640/;s/image_height: 240/image_height: 480/'
cam nan_dist 's/data: \[ -5\.99[0-9e+-.]*,/data: [ .Nan,/'
cam huge_dist 's/data: \[ -5\.99[0-9e+-.]*,/data: [ 1.0e+300,/'
cam nan_tvec '/^tvec/,/data/{s/data: \[ [0-9e+.-]*,/data: [ .Nan,/}'
cam huge_tvec '/^tvec/,/data/{s/data: \[ [0-9e+.-]*,/data: [ 1.0e+300,/}'
cam inf_rvec '/^rvec/,/data/{s/data: \[ [0-9e+.-]*,/data: [ .Inf,/}'
cam no_matrix '/^camera_matrix/,/data/d'
cam text_width 's/image_width: 320/image_width: wide/'
sed -e 's/cols: 5/cols: 3/' "$F/cam1.yaml" >"$B/dist_cols.yaml"
printf '{"image_width": 320}\n' >"$B/json_camera.yaml"
# CSVs: BALL.csv / truth layout (frame,time_s,x_m,y_m,z_m,n_cams).
ballcsv() {  # ballcsv NAME LINE_TO_APPEND_OR_REPLACE_3
  { head -3 "$F/truth.csv"; printf '%b\n' "$2"; tail -n +5 "$F/truth.csv"; } >"$B/$1.csv"
}
ballcsv nan_x '2,0.0333,nan,1,0.11,3'
ballcsv inf_z '2,0.0333,1,1,inf,3'
ballcsv huge_y '2,0.0333,1,1e300,0.11,3'
ballcsv huge_frame '2000000000,0.0333,1,1,0.11,3'
ballcsv neg_frame '-5,0.0333,1,1,0.11,3'
ballcsv nan_time '2,nan,1,1,0.11,3'
ballcsv huge_time '2,1e300,1,1,0.11,3'
ballcsv text_cell '2,0.0333,one,1,0.11,3'
ballcsv ragged '2,0.0333,1'
ballcsv dup_frame '1,0.0167,1,1,0.11,3'
# Timestamps (frame,time_s): text, negative or non-increasing times, a negative frame.
tscsv() { { printf 'frame,time_s\n0,0\n1,0.0167\n'; printf '%b\n' "$2"; printf '3,0.05\n4,0.0667\n5,0.0833\n'; } >"$B/$1.csv"; }
tscsv ts_text '2,soon'
tscsv ts_negative '2,-0.0333'
tscsv ts_backwards '2,0.01'
tscsv ts_neg_frame '-2,0.0333'
head -1 "$F/truth.csv" >"$B/header_only.csv"
printf 'a,b,c\n1,2,3\n' >"$B/wrong_columns.csv"
# Detections CSV (frame,time_s,u,v,radius_px,score).
detcsv() { { head -2 "$F/det_cam1.csv"; printf '%b\n' "$2"; tail -n +4 "$F/det_cam1.csv"; } >"$B/$1.csv"; }
detcsv det_nan_u '2,0.0333,nan,50,3,1'
detcsv det_huge_frame '2000000000,0.0333,50,50,3,1'
detcsv det_inf_time '2,inf,50,50,3,1'
# TRACKS.csv.
trk() { { head -3 "$F/TRACKS.csv"; printf '%b\n' "$2"; tail -n +5 "$F/TRACKS.csv"; } >"$B/$1.csv"; }
trk tracks_nan_x '2,1,11,50,20,60,0.9,nan,1.0,0.04'
trk tracks_huge_x '2,1,11,50,20,60,0.9,1e300,1.0,0.04'
trk tracks_huge_frame '2000000000,1,11,50,20,60,0.9,1.5,1.0,0.04'
trk tracks_dup '1,1,11,50,20,60,0.9,1.5,1.0,0.0'
trk tracks_neg_box '2,1,11,50,-20,60,0.9,1.5,1.0,0.04'
trk tracks_nan_time '2,1,11,50,20,60,0.9,1.5,1.0,nan'
printf '1,-1,10,50,nan,60,0.9\n' >"$B/det_nan.txt"
printf '2000000000,-1,10,50,20,60,0.9\n' >"$B/det_huge_frame.txt"
# JSON files.
mkbad not_json.json '{"name": "x", '
mkbad nan_token.json '{"length": NaN}'
python3 -c 'print("[" * 100000 + "]" * 100000)' >"$B/deep.json" 2>/dev/null ||
  awk 'BEGIN{for(i=0;i<100000;i++)printf "[";for(i=0;i<100000;i++)printf "]";print ""}' >"$B/deep.json"
sed -e 's/^  "length_m": *[0-9.e+]*/  "length_m": 1e308/' "$F/field.json" >"$B/field_huge.json"
sed -e 's/^  "length_m": *[0-9.e+]*/  "length_m": -18/' "$F/field.json" >"$B/field_neg.json"
sed -e 's/^  "length_m": *[0-9.e+]*/  "length_m": "long"/' "$F/field.json" >"$B/field_type.json"
printf '[]\n' >"$B/array.json"
sed -e 's/\[0, -8, 4\]/[1e300, -8, 4]/' "$F/rig.json" >"$B/rig_huge.json"
sed -e 's/"image_width": 640/"image_width": 2000000000/' "$F/rig.json" >"$B/rig_width.json"
sed -e 's/"hfov_deg": 70/"hfov_deg": 179.999/' "$F/rig.json" >"$B/rig_hfov.json"
printf '{"cameras": []}\n' >"$B/rig_empty.json"
printf '[{"name": "box", "polygon": [[0, 0], [1e300, 0], [5, 3]]}]\n' >"$B/zones_huge.json"
printf '[{"name": "box", "polygon": [[0, 0]]}]\n' >"$B/zones_short.json"
printf '[{"merge": [1]}]\n' >"$B/edits_short.json"
printf '[{"rename": {"1": "x"}}]\n' >"$B/edits_type.json"
printf '{"mounts": [{"point": [0, "a", 4]}]}\n' >"$B/mounts_type.json"
sed -e 's/"hfov_deg": *[0-9.]*/"hfov_deg": 1e300/' "$F/scene.json" >"$B/scene_hfov.json"
sed -e 's/"width": *[0-9]*/"width": 100000/' "$F/scene.json" >"$B/scene_width.json"
printf '<dataset><frame number="nan"></frame></dataset>\n' >"$B/pets_nan.xml"
printf '<dataset><frame number="2000000000"><objectlist><object id="1"><box h="60" w="20" xc="20" yc="80"/></object></objectlist></frame></dataset>\n' >"$B/pets_huge.xml"
printf 'u,v,name\n10,20,nowhere\n' >"$B/points_unknown.csv"
printf 'u,v,name\nnan,120,centre_spot\n160,20,halfway_top\n160,220,halfway_bottom\n10,220,corner_left_bottom\n' >"$B/points_nan.csv"
ln -s "$B/does_not_exist.csv" "$B/dangling.csv"
ln -s "$B/does_not_exist.yaml" "$B/dangling.yaml"

# Manifest of everything the cases may not change.
manifest() {
  (cd "$W" && find fx bad out -printf '%p %y %l %m\n' | LC_ALL=C sort &&
    find fx bad out -type f -print0 | LC_ALL=C sort -z | xargs -0 md5sum)
}
cp -a "$F" "$S/fx.pristine"; cp -a "$B" "$S/bad.pristine"; cp -a "$O" "$S/out.pristine"
manifest >"$S/manifest.before"

total=0 failed=0 nlisted=0
declare -a failures=()
restore() {
  rm -rf "$F" "$B" "$O"
  cp -a "$S/fx.pristine" "$F"; cp -a "$S/bad.pristine" "$B"; cp -a "$S/out.pristine" "$O"
}
norm() { tr 'A-Z' 'a-z' | tr -d -- '-_ '; }
# names EXPECT: the stderr line names EXPECT: a file name as it is; an option (opt:NAME) by its
# name or by every word of it (--inlier-px: 'inlier_threshold_px').
names() {
  local line
  line=$(tr 'A-Z' 'a-z' <"$S/stderr")
  if [[ "$1" == opt:* ]]; then
    local o="${1#opt:}" w
    [[ "$line" == *"$o"* ]] && return 0
    for w in ${o//-/ }; do [[ "$line" == *"$w"* ]] || return 1; done
    return 0
  fi
  [[ "$line" == *"$(printf '%s' "$1" | tr 'A-Z' 'a-z')"* ]]
}

# c NAME EXPECT [QUICK] -- ARGS...: one case; EXPECT is what the one stderr line must name.
c() {
  local name="$1" expect="$2" quick=0
  shift 2
  case "$1" in quick) quick=1; shift ;; --) shift ;; esac
  [ "${1:-}" = -- ] && shift
  [ -n "$ONLY" ] && ! [[ "$name" =~ $ONLY ]] && return
  [ $QUICK = 1 ] && ! [[ "$name" =~ $QUICK_CASES ]] && return
  index=$((index + 1))
  [ $(((index - 1) % SHARD_N)) = "$SHARD_I" ] || return
  if [ $LIST = 1 ]; then echo "$name"; nlisted=$((nlisted + 1)); return; fi
  total=$((total + 1))
  local why=""
  (
    cd "$W" || exit 99
    # A safety net for the machine (the check is on RSS below); not for ASan builds, whose shadow
    # memory is terabytes of address space.
    [ "$ASAN" = 1 ] || ulimit -v 8388608
    exec /usr/bin/time -f '%M' -o "$S/rss" timeout -k 5 "$TIME_LIMIT_S" "$FV" "$@" \
      >"$S/stdout" 2>"$S/stderr" </dev/null
  )
  local rc=$?
  local rss
  rss=$(tail -1 "$S/rss" 2>/dev/null)
  [[ "$rss" =~ ^[0-9]+$ ]] || rss=0
  local lines
  lines=$(wc -l <"$S/stderr")
  if [ $rc = 124 ] || [ $rc = 137 ]; then
    why="timed out (${TIME_LIMIT_S} s)"
  elif [ $rc -gt 128 ]; then
    why="killed by signal $((rc - 128))"
  elif [ $rc = 0 ]; then
    why="exit 0"
  elif [ "$lines" != 1 ] || [ "$(wc -c <"$S/stderr")" -le 1 ]; then
    why="stderr has $lines lines"
  elif ! grep -q "error" "$S/stderr"; then
    why="stderr line is not an error"
  elif [ -n "$expect" ] && ! names "$expect"; then
    why="error does not name '$expect'"
  fi
  if [ "$rss" -gt "$MEM_LIMIT_KB" ]; then why="${why:+$why; }memory $((rss / 1024)) MB"; fi
  if ! manifest >"$S/manifest.after" 2>/dev/null || ! cmp -s "$S/manifest.before" "$S/manifest.after"; then
    local changed
    changed=$(diff "$S/manifest.before" "$S/manifest.after" | grep '^[<>]' | awk '{print $2}' |
      sort -u | head -3 | tr '\n' ' ')
    why="${why:+$why; }files changed: $changed"
    restore
  fi
  if [ -n "$why" ]; then
    failed=$((failed + 1))
    failures+=("$name")
    echo "FAIL $name: $why"
    echo "     fieldvision $*"
    head -3 "$S/stderr" | cut -c1-300 | sed 's/^/     | /'
  elif [ $VERBOSE = 1 ]; then
    echo "ok   $name ($((rss / 1024)) MB): $(head -1 "$S/stderr" | cut -c1-150)"
  fi
}

# ---- the cases
CAM_BAD="nan_focal inf_focal neg_focal zero_focal huge_focal huge_width neg_height zero_width
  wrong_size nan_dist huge_dist nan_tvec huge_tvec inf_rvec no_matrix text_width dist_cols
  json_camera truncated empty binary folder dangling missing"
VIDEO_BAD="empty binary truncated text folder missing"
CSV_BAD="nan_x inf_z huge_y huge_frame neg_frame nan_time huge_time text_cell ragged dup_frame
  header_only wrong_columns empty binary folder dangling missing"
TRACKS_BAD="tracks_nan_x tracks_huge_x tracks_huge_frame tracks_dup tracks_neg_box tracks_nan_time
  wrong_columns empty binary folder missing"
JSON_BAD="not_json nan_token deep array empty binary truncated folder missing"
FIELD_BAD="$JSON_BAD field_huge field_neg field_type"
# --quick: these cases only (one or two per input kind, each from an issue 18 finding).
QUICK_CASES='^(detect --camera nan_focal|detect --video truncated|detect out=same|ball --truth=out'
QUICK_CASES+='|ball --camera huge_width|ball --detections det_huge_frame|ball --video truncated'
QUICK_CASES+='|ball --timestamps ts_backwards|calibrate refine --overlay=image|trajectory --images=file'
QUICK_CASES+='|calibrate refine out=same'
QUICK_CASES+='|trajectory out=link|trajectory --gravity=nan|trajectory --in binary|eval ball --est nan_x'
QUICK_CASES+='|eval tracks --gt tracks_dup|stats --tracks tracks_nan_x|stats --zones zones_huge'
QUICK_CASES+='|stats --fps 1e-300|field show field_huge|plan --step tiny|plan --rig rig_huge'
QUICK_CASES+='|synth 16384x16384|players --input-width huge|calibrate check --table=image'
QUICK_CASES+='|color learn --mask-out=video|calibrate extrinsics --camera nan_focal|tracks edit out=same'
QUICK_CASES+='|eval import-pets out=same|unknown option)$'
QUICK_SET=" "
path_of() {  # path_of NAME EXT: the bad file's path (missing: a name that does not exist)
  case "$1" in
    missing) echo "$B/missing.$2" ;;
    *) if [ -e "$B/$1.$2" ] || [ -L "$B/$1.$2" ]; then echo "$B/$1.$2"; else echo "$B/$1.csv"; fi ;;
  esac
}
is_quick() { [[ "$QUICK_SET" == *" $1 "* ]] && echo quick || echo --; }

# sweep_file CMD_LABEL KIND EXT "BAD LIST" ARGS... with @ where the bad file goes
sweep_file() {
  local label="$1" ext="$2" list="$3"
  shift 3
  local v p args a
  for v in $list; do
    p=$(path_of "$v" "$ext")
    args=()
    for a in "$@"; do args+=("${a//@/$p}"); done
    c "$label $v" "$(basename "$p")" "$(is_quick "$v")" -- "${args[@]}"
  done
}
# sweep_out CMD_LABEL INPUT ARGS... with @ where the output goes: the output is the input, a link
# to it, an existing folder, a device, or in a missing folder.
sweep_out() {
  local label="$1" input="$2"
  shift 2
  local kind p args a
  for kind in same link folder device nofolder; do
    case $kind in
      same) p="$input" ;;
      link) p="$O/link_$(basename "$input")" ;;
      folder) p="$O/olddir" ;;
      device) p="$DEV" ;;
      nofolder) p="$O/no/such/folder/out.${input##*.}" ;;
    esac
    args=()
    for a in "$@"; do args+=("${a//@/$p}"); done
    c "$label out=$kind" "$(basename "$p")" "$( [ $kind = same ] && echo quick || echo --)" \
      -- "${args[@]}"
  done
}
# sweep_opt CMD_LABEL OPTION "VALUES" ARGS...: ARGS is a good command line; OPTION VALUE appended.
sweep_opt() {
  local label="$1" opt="$2" values="$3" v
  shift 3
  for v in $values; do
    [ "$v" = EMPTY ] && v=""
    c "$label $opt=$v" "opt:${opt#--}" "$( [ "$v" = nan ] && echo quick || echo --)" -- "$@" "$opt" "$v"
  done
}
NUMS="nan inf -inf 1e300 -1e300 abc EMPTY"
POS="nan inf 1e300 0 -1 abc"
INTS="nan 1e300 -5 99999999999999999999 abc"

OUTCSV="$O/old.csv"
# detect
sweep_file "detect --camera" yaml "$CAM_BAD" detect --camera @ --video "$F/cam1.avi" --out "$OUTCSV" --no-progress
sweep_file "detect --video" avi "$VIDEO_BAD" detect --camera "$F/cam1.yaml" --video @ --out "$OUTCSV" --no-progress
sweep_file "detect --field" json "$FIELD_BAD" detect --camera "$F/cam1.yaml" --video "$F/cam1.avi" --field @ --out "$OUTCSV" --no-progress
sweep_file "detect --color" json "$JSON_BAD colour_bad_shape" detect --video "$F/cam1.avi" --color @ --out "$OUTCSV" --no-progress
sweep_out "detect" "$F/cam1.avi" detect --video "$F/cam1.avi" --out @ --no-progress
for o in --ball-diameter --min-radius --max-radius; do
  sweep_opt detect $o "$POS" detect --camera "$F/cam1.yaml" --video "$F/cam1.avi" --out "$OUTCSV" --no-progress
done
sweep_opt detect --step "$INTS 0" detect --video "$F/cam1.avi" --out "$OUTCSV" --no-progress
sweep_opt detect --max-frames "$INTS" detect --video "$F/cam1.avi" --out "$OUTCSV" --no-progress
# (a folder is a --draw output of its own: the annotated frames as JPEGs)
sweep_opt detect --draw "$DEV $F/cam1.avi" detect --video "$F/cam1.avi" --out "$O/new.csv" --no-progress
# ball
BALL2=(ball --camera "$F/cam1.yaml" --video "$F/cam1.avi" --camera "$F/cam2.yaml" --video "$F/cam2.avi" --no-progress)
sweep_file "ball --camera" yaml "$CAM_BAD" ball --camera @ --video "$F/cam1.avi" --camera "$F/cam2.yaml" --video "$F/cam2.avi" --out "$OUTCSV" --no-progress
sweep_file "ball --video" avi "$VIDEO_BAD" ball --camera "$F/cam1.yaml" --video @ --camera "$F/cam2.yaml" --video "$F/cam2.avi" --out "$OUTCSV" --no-progress
sweep_file "ball --truth" csv "$CSV_BAD" "${BALL2[@]}" --truth @ --out "$O/new.csv"
sweep_file "ball --detections" csv "$CSV_BAD det_nan_u det_huge_frame det_inf_time" ball --camera "$F/cam1.yaml" --detections @ --camera "$F/cam2.yaml" --detections "$F/det_cam2.csv" --out "$OUTCSV" --no-progress
sweep_file "ball --timestamps" csv "nan_time huge_time ts_text ts_negative ts_backwards ts_neg_frame ragged header_only empty binary missing" "${BALL2[@]}" --timestamps @ --timestamps "$F/det_cam2.csv" --out "$OUTCSV"
sweep_file "ball --field" json "$FIELD_BAD" "${BALL2[@]}" --field @ --out "$OUTCSV"
sweep_out "ball" "$F/cam1.avi" "${BALL2[@]}" --out @
c "ball --truth=out" "truth.csv" quick -- "${BALL2[@]}" --truth "$F/truth.csv" --out "$F/truth.csv"
c "ball cameras/videos mismatch" "video" -- ball --camera "$F/cam1.yaml" --video "$F/cam1.avi" --camera "$F/cam2.yaml" --out "$OUTCSV" --no-progress
c "ball one camera" "camera" -- ball --camera "$F/cam1.yaml" --video "$F/cam1.avi" --out "$OUTCSV" --no-progress
c "ball same camera twice" "cam1" -- ball --camera "$F/cam1.yaml" --video "$F/cam1.avi" --camera "$F/cam1.yaml" --video "$F/cam1.avi" --out "$OUTCSV" --no-progress
c "ball videos of other sizes" "" -- ball --camera "$F/cam1.yaml" --video "$F/cam1.avi" --camera "$B/wrong_size.yaml" --video "$F/cam2.avi" --out "$OUTCSV" --no-progress
c "ball --flights without --detections" "flights" -- "${BALL2[@]}" --flights "$O/new.json" --out "$OUTCSV"
c "ball --sync bogus" "sync" -- "${BALL2[@]}" --sync bogus --out "$OUTCSV"
for o in --ball-diameter --det-sigma --tolerance --inlier-px; do sweep_opt ball $o "$POS" "${BALL2[@]}" --out "$OUTCSV"; done
sweep_opt ball --max-frames "$INTS" "${BALL2[@]}" --out "$OUTCSV"
sweep_opt ball --full-scan-every "$INTS 0" "${BALL2[@]}" --out "$OUTCSV"
# trajectory
# (trajectory skips a bad row with a warning naming file:line, by design: whole-file cases only)
sweep_file "trajectory --in" csv "header_only wrong_columns empty binary folder dangling missing" trajectory --in @ --out "$O/old.json"
sweep_file "trajectory --field" json "$FIELD_BAD" trajectory --in "$F/BALL.csv" --field @ --out "$O/old.json"
sweep_out "trajectory" "$F/BALL.csv" trajectory --in "$F/BALL.csv" --out @
c "trajectory --smoothed=in" "BALL.csv" -- trajectory --in "$F/BALL.csv" --out "$O/new.json" --smoothed "$F/BALL.csv"
c "trajectory --report=in" "BALL.csv" -- trajectory --in "$F/BALL.csv" --out "$O/new.json" --report "$F/BALL.csv"
c "trajectory --images=file" "old.png" -- trajectory --in "$F/BALL.csv" --out "$O/new.json" --images "$O/old.png"
c "trajectory --line without field" "field" -- trajectory --in "$F/BALL.csv" --out "$O/new.json" --line touch
c "trajectory --line unknown" "nosuchline" -- trajectory --in "$F/BALL.csv" --out "$O/new.json" --field robocup-msl --line nosuchline
for o in --ball-diameter --gravity --ball-mass; do sweep_opt trajectory $o "$POS" trajectory --in "$F/BALL.csv" --out "$O/new.json"; done
for o in --ground-z --noise --accel-slack --predict-fraction; do sweep_opt trajectory $o "nan inf 1e300 -1e300 abc" trajectory --in "$F/BALL.csv" --out "$O/new.json"; done
# plan
sweep_file "plan --rig" json "$JSON_BAD rig_huge rig_width rig_empty" plan --rig @ --out "$O/plan" --no-progress
sweep_file "plan --camera" yaml "${CAM_BAD/wrong_size/}" plan --camera @ --camera "$F/cam2.yaml" --out "$O/plan" --no-progress
sweep_file "plan --field" json "$FIELD_BAD" plan --rig "$F/rig.json" --field @ --out "$O/plan" --no-progress
sweep_file "plan --mounts" json "$JSON_BAD mounts_type" plan --optimize --field robocup-msl --mounts @ --out "$O/plan" --no-progress
c "plan --out=file" "old.csv" -- plan --rig "$F/rig.json" --out "$O/old.csv" --no-progress
c "plan --out=device" "$DEV" -- plan --rig "$F/rig.json" --out "$DEV" --no-progress
c "plan no rig" "rig" -- plan --out "$O/plan" --no-progress
for o in --step --ball-diameter --min-ball-px --noise-px --hfov --search-step; do sweep_opt plan $o "$POS" plan --rig "$F/rig.json" --out "$O/plan" --no-progress; done
for o in --height-above --margin-px --error-weight --perimeter-offset --mount-height; do sweep_opt plan $o "nan inf 1e300 abc" plan --rig "$F/rig.json" --out "$O/plan" --no-progress; done
for o in --map-width --cameras --width --height --iterations --restarts; do sweep_opt plan $o "$INTS 0" plan --rig "$F/rig.json" --optimize --out "$O/plan" --no-progress; done
c "plan --step tiny" "step" -- plan --field fifa --rig "$F/rig.json" --step 1e-4 --out "$O/plan" --no-progress
c "plan --good-angle reversed" "good" -- plan --rig "$F/rig.json" --good-angle 120 40 --out "$O/plan" --no-progress
# players
PL=(players --video "$F/cam1.avi" --detector motion --no-progress)
sweep_file "players --video" avi "$VIDEO_BAD" players --video @ --detector motion --out "$OUTCSV" --no-progress
sweep_file "players --camera" yaml "$CAM_BAD" "${PL[@]}" --camera @ --out "$OUTCSV"
sweep_file "players --field" json "$FIELD_BAD" "${PL[@]}" --camera "$F/cam1.yaml" --field @ --out "$OUTCSV"
sweep_file "players --detections" txt "det_nan det_huge_frame empty binary missing" players --video "$F/cam1.avi" --detections @ --out "$OUTCSV" --no-progress
sweep_file "players --onnx" txt "empty binary missing" "${PL[@]}" --onnx @ --out "$OUTCSV"
sweep_out "players" "$F/cam1.avi" "${PL[@]}" --out @
c "players --mot-out=video" "cam1.avi" -- "${PL[@]}" --out "$O/new.csv" --mot-out "$F/cam1.avi"
c "players --draw=video" "cam1.avi" -- "${PL[@]}" --out "$O/new.csv" --draw "$F/cam1.avi"
c "players --save-detections=video" "cam1.avi" -- "${PL[@]}" --out "$O/new.csv" --save-detections "$F/cam1.avi"
c "players --margin without field" "margin" -- "${PL[@]}" --out "$O/new.csv" --margin 2
for o in --score --min-height --stitch-gap --stitch-appearance --smooth-accel --fps; do sweep_opt players $o "nan inf 1e300 -1 abc" "${PL[@]}" --out "$O/new.csv"; done
for o in --input-width --threads --max-lost --max-frames --interpolate --min-track-frames; do sweep_opt players $o "$INTS" "${PL[@]}" --out "$O/new.csv"; done
c "players --input-width huge" "opt:input-width" -- players --video "$F/cam1.avi" --input-width 32000 --out "$O/new.csv" --no-progress
# stats
ST=(stats --tracks "$F/TRACKS.csv" --field robocup-msl --no-video)
sweep_file "stats --tracks" csv "$TRACKS_BAD" stats --tracks @ --field robocup-msl --out "$O/stats" --no-video
sweep_file "stats --field" json "$FIELD_BAD" stats --tracks "$F/TRACKS.csv" --field @ --out "$O/stats" --no-video
sweep_file "stats --zones" json "$JSON_BAD zones_huge zones_short" "${ST[@]}" --zones @ --out "$O/stats"
sweep_file "stats --teams" csv "wrong_columns empty binary folder missing" "${ST[@]}" --teams @ --out "$O/stats"
c "stats --out=file" "old.csv" -- "${ST[@]}" --out "$O/old.csv"
c "stats --out=device" "$DEV" -- "${ST[@]}" --out "$DEV"
c "stats radar frame 2e9" "frame" -- stats --tracks "$B/tracks_huge_frame.csv" --field robocup-msl --out "$O/stats"
for o in --fps --smooth --sprint-speed; do sweep_opt stats $o "$POS" "${ST[@]}" --out "$O/stats"; done
c "stats --fps 1e-300" "fps" -- "${ST[@]}" --fps 1e-300 --out "$O/stats"
# tracks edit / draw
sweep_file "tracks edit --tracks" csv "$TRACKS_BAD" tracks edit --tracks @ --edits "$F/edits.json" --out "$OUTCSV"
sweep_file "tracks edit --edits" json "$JSON_BAD edits_short edits_type" tracks edit --tracks "$F/TRACKS.csv" --edits @ --out "$OUTCSV"
sweep_file "tracks edit --roster" csv "wrong_columns empty binary folder missing" tracks edit --tracks "$F/TRACKS.csv" --edits "$F/edits.json" --roster @ --out "$OUTCSV"
sweep_out "tracks edit" "$F/TRACKS.csv" tracks edit --tracks "$F/TRACKS.csv" --edits "$F/edits.json" --out @
sweep_file "tracks draw --tracks" csv "$TRACKS_BAD" tracks draw --tracks @ --video "$F/cam1.avi" --out "$O/old.avi"
sweep_file "tracks draw --video" avi "$VIDEO_BAD" tracks draw --tracks "$F/TRACKS.csv" --video @ --out "$O/old.avi"
sweep_file "tracks draw --camera" yaml "$CAM_BAD" tracks draw --tracks "$F/TRACKS.csv" --video "$F/cam1.avi" --camera @ --field robocup-msl --out "$O/old.avi"
sweep_out "tracks draw" "$F/cam1.avi" tracks draw --tracks "$F/TRACKS.csv" --video "$F/cam1.avi" --out @
sweep_opt "tracks draw" --fps "$POS" tracks draw --tracks "$F/TRACKS.csv" --video "$F/cam1.avi" --out "$O/new.avi"
sweep_opt "tracks draw" --max-frames "$INTS" tracks draw --tracks "$F/TRACKS.csv" --video "$F/cam1.avi" --out "$O/new.avi"
# calibrate
sweep_file "calibrate intrinsics --images" avi "$VIDEO_BAD" calibrate intrinsics --images @ --cols 9 --rows 6 --square 0.025 --out "$O/old.yaml" --quiet
sweep_out "calibrate intrinsics" "$F/cam1.avi" calibrate intrinsics --images "$F/cam1.avi" --cols 9 --rows 6 --square 0.025 --out @ --quiet
for o in --square --marker --outlier-factor --subpix-cap; do sweep_opt "calibrate intrinsics" $o "nan inf 1e300 -1 abc" calibrate intrinsics --images "$F/frames" --cols 9 --rows 6 --square 0.025 --out "$O/new.yaml" --quiet; done
for o in --cols --rows --model --subpix-window --max-frames; do sweep_opt "calibrate intrinsics" $o "$INTS 0" calibrate intrinsics --images "$F/frames" --cols 9 --rows 6 --square 0.025 --out "$O/new.yaml" --quiet; done
EX=(calibrate extrinsics --field robocup-msl)
sweep_file "calibrate extrinsics --camera" yaml "${CAM_BAD/wrong_size/}" "${EX[@]}" --camera @ --points "$F/points.csv" --out "$O/old.yaml"
sweep_file "calibrate extrinsics --points" csv "$CSV_BAD points_unknown points_nan" "${EX[@]}" --camera "$F/cam1.yaml" --points @ --out "$O/old.yaml"
sweep_file "calibrate extrinsics --field" json "$FIELD_BAD" calibrate extrinsics --camera "$F/cam1.yaml" --points "$F/points.csv" --field @ --out "$O/old.yaml"
sweep_out "calibrate extrinsics" "$F/points.csv" "${EX[@]}" --camera "$F/cam1.yaml" --points "$F/points.csv" --out @
c "calibrate extrinsics --image-size bad" "opt:image-size" -- "${EX[@]}" --image-size 0x-5 --points "$F/points.csv" --out "$O/new.yaml"
sweep_opt "calibrate extrinsics" --threshold "$POS" "${EX[@]}" --camera "$F/cam1.yaml" --points "$F/points.csv" --out "$O/new.yaml"
RF=(calibrate refine --field robocup-msl)
sweep_file "calibrate refine --camera" yaml "$CAM_BAD" "${RF[@]}" --camera @ --image "$FRAME" --out "$O/old.yaml"
sweep_file "calibrate refine --image" png "empty binary truncated folder missing" "${RF[@]}" --camera "$F/cam1.yaml" --image @ --out "$O/old.yaml"
sweep_file "calibrate refine --field" json "$FIELD_BAD" calibrate refine --camera "$F/cam1.yaml" --image "$FRAME" --field @ --out "$O/old.yaml"
sweep_out "calibrate refine" "$FRAME" "${RF[@]}" --camera "$F/cam1.yaml" --image "$FRAME" --out @
c "calibrate refine --overlay=image" "$(basename "$FRAME")" -- "${RF[@]}" --camera "$F/cam1.yaml" --image "$FRAME" --out "$O/new.yaml" --overlay "$FRAME"
sweep_opt "calibrate refine" --lut-resolution "$POS" "${RF[@]}" --camera "$F/cam1.yaml" --image "$FRAME" --out "$O/new.yaml"
CK=(calibrate check --field robocup-msl)
sweep_file "calibrate check --camera" yaml "$CAM_BAD" "${CK[@]}" --camera @ --image "$FRAME" --out "$O/old.png"
sweep_file "calibrate check --image" png "empty binary truncated folder missing" "${CK[@]}" --camera "$F/cam1.yaml" --image @ --out "$O/old.png"
sweep_file "calibrate check --points" csv "$CSV_BAD points_unknown points_nan" "${CK[@]}" --camera "$F/cam1.yaml" --image "$FRAME" --points @ --out "$O/new.png"
sweep_out "calibrate check" "$FRAME" "${CK[@]}" --camera "$F/cam1.yaml" --image "$FRAME" --out @
c "calibrate check --table=image" "$(basename "$FRAME")" -- "${CK[@]}" --camera "$F/cam1.yaml" --image "$FRAME" --points "$F/points.csv" --table "$FRAME" --out "$O/new.png"
sweep_file "calibrate rig --camera" yaml "${CAM_BAD/wrong_size/}" calibrate rig --field robocup-msl --camera @ --camera "$F/cam2.yaml" --points "$F/points.csv" --points "$F/points.csv" --out-dir "$O/rig"
sweep_file "calibrate rig --points" csv "$CSV_BAD points_unknown points_nan" calibrate rig --field robocup-msl --camera "$F/cam1.yaml" --camera "$F/cam2.yaml" --points @ --points "$F/points.csv" --out-dir "$O/rig"
c "calibrate rig --out-dir=file" "old.csv" -- calibrate rig --field robocup-msl --camera "$F/cam1.yaml" --camera "$F/cam2.yaml" --points "$F/points.csv" --points "$F/points.csv" --out-dir "$O/old.csv"
c "calibrate rig cameras/points mismatch" "points" -- calibrate rig --field robocup-msl --camera "$F/cam1.yaml" --camera "$F/cam2.yaml" --points "$F/points.csv" --out-dir "$O/rig"
sweep_file "calibrate multi --views" avi "$VIDEO_BAD" calibrate multi --cols 9 --rows 6 --square 0.025 --views a=@ --views b="$F/cam2.avi" --out "$O/multi" --quiet
sweep_file "calibrate multi --intrinsics" yaml "$CAM_BAD" calibrate multi --cols 9 --rows 6 --square 0.025 --views a="$F/cam1.avi" --views b="$F/cam2.avi" --intrinsics a=@ --out "$O/multi" --quiet
c "calibrate multi one view" "views" -- calibrate multi --cols 9 --rows 6 --square 0.025 --views a="$F/cam1.avi" --out "$O/multi" --quiet
c "calibrate multi --views no name" "views" -- calibrate multi --cols 9 --rows 6 --square 0.025 --views "$F/cam1.avi" --views b="$F/cam2.avi" --out "$O/multi" --quiet
sweep_file "calibrate import --tsai" xml "empty binary pets_nan folder missing" calibrate import --tsai @ --out "$O/old.yaml"
sweep_file "calibrate import --toml" txt "empty binary missing" calibrate import --toml @ --out "$O/imp"
sweep_file "calibrate import --opencv-stereo" yaml "empty binary truncated missing nan_focal" calibrate import --opencv-stereo @ --image-size 320x240 --out "$O/imp"
c "calibrate import --units bogus" "units" -- calibrate import --toml "$B/empty.txt" --units furlong --out "$O/imp"
# color learn
CL=(color learn --video "$F/cam1.avi")
sweep_file "color learn --video" avi "empty binary text folder missing" color learn --video @ --roi 10,10,20,20 --out "$O/old.json"
sweep_out "color learn" "$F/cam1.avi" "${CL[@]}" --roi 10,10,20,20 --out @
c "color learn --mask-out=video" "cam1.avi" -- "${CL[@]}" --roi 10,10,20,20 --out "$O/new.json" --mask-out "$F/cam1.avi"
for v in "nan,1,2,3" "-5,-5,2,2" "0,0,0,0" "1e300,0,5,5" "10,10,5000,5000" "a,b,c,d" "1,2,3"; do
  c "color learn --roi=$v" "roi" -- "${CL[@]}" --roi "$v" --out "$O/new.json"
done
for v in "nan,1" "1e300,5" "-3,-3" "5;6" "x"; do c "color learn --points=$v" "points" -- "${CL[@]}" --points "$v" --out "$O/new.json"; done
sweep_opt "color learn" --frame "$INTS 1000" "${CL[@]}" --roi 10,10,20,20 --out "$O/new.json"
sweep_opt "color learn" --max-background "nan inf 1e300 -1 abc" "${CL[@]}" --roi 10,10,20,20 --out "$O/new.json"
c "color learn neither points nor roi" "" -- "${CL[@]}" --out "$O/new.json"
# eval
sweep_file "eval ball --truth" csv "$CSV_BAD" eval ball --truth @ --est "$F/BALL.csv"
sweep_file "eval ball --est" csv "$CSV_BAD" eval ball --truth "$F/truth.csv" --est @
sweep_opt "eval ball" --outlier "$POS" eval ball --truth "$F/truth.csv" --est "$F/BALL.csv"
sweep_opt "eval ball" --min-cams "$INTS" eval ball --truth "$F/truth.csv" --est "$F/BALL.csv"
sweep_file "eval tracks --gt" csv "$TRACKS_BAD" eval tracks --gt @ --est "$F/TRACKS.csv"
sweep_file "eval tracks --est" csv "$TRACKS_BAD" eval tracks --gt "$F/TRACKS.csv" --est @
sweep_file "eval tracks --gt xml" xml "pets_nan pets_huge empty binary" eval tracks --gt @ --est "$F/TRACKS.csv"
sweep_out "eval tracks" "$F/TRACKS.csv" eval tracks --gt "$F/TRACKS.csv" --est "$F/TRACKS.csv" --json @
sweep_opt "eval tracks" --iou "nan inf 1e300 -1 2 abc" eval tracks --gt "$F/TRACKS.csv" --est "$F/TRACKS.csv"
# (a negative offset is one: an estimate numbered from 1 against truth from 0)
sweep_opt "eval tracks" --frame-offset "nan 1e300 99999999999999999999 abc" eval tracks --gt "$F/TRACKS.csv" --est "$F/TRACKS.csv"
sweep_file "eval detect --video" avi "$VIDEO_BAD" eval detect --video @ --labels "$F/labels.csv" --no-progress
sweep_file "eval detect --camera" yaml "$CAM_BAD" eval detect --video "$F/frames" --labels "$F/labels" --camera @ --no-progress
sweep_file "eval detect --labels" csv "empty binary missing" eval detect --video "$F/frames" --labels @ --no-progress
sweep_out "eval detect" "$FRAME" eval detect --video "$F/frames" --labels "$F/labels" --out @ --no-progress
for o in --min-radius --max-radius --grow; do sweep_opt "eval detect" $o "nan inf 1e300 -1 abc" eval detect --video "$F/frames" --labels "$F/labels" --no-progress; done
sweep_opt "eval detect" --class "$INTS" eval detect --video "$F/frames" --labels "$F/labels" --no-progress
sweep_file "eval import-pets --xml" xml "empty binary pets_nan pets_huge folder missing" eval import-pets --xml @ --out "$OUTCSV"
sweep_out "eval import-pets" "$F/pets.xml" eval import-pets --xml "$F/pets.xml" --out @
# field
sweep_file "field show" json "$FIELD_BAD" field show @
sweep_file "field draw" json "$FIELD_BAD" field draw @ --out "$O/old.png"
sweep_out "field draw" "$F/field.json" field draw "$F/field.json" --out @
sweep_opt "field draw" --width "$INTS 50 30000" field draw robocup-msl --out "$O/new.png"
c "field unknown" "rugby" -- field show rugby
# synth
sweep_file "synth --scene" json "$JSON_BAD scene_hfov scene_width" synth --scene @ --out "$O/synth" --quiet
c "synth --out=file" "old.csv" -- synth --preset static --frames 2 --width 64 --height 48 --out "$O/old.csv" --quiet
c "synth --out=device" "$DEV" -- synth --preset static --frames 2 --width 64 --height 48 --out "$DEV" --quiet
c "synth --preset bogus" "preset" -- synth --preset bogus --out "$O/synth" --quiet
c "synth 16384x16384" "width" -- synth --preset static --frames 1 --width 16384 --height 16384 --out "$O/synth" --quiet
for o in --frames --width --height; do sweep_opt synth $o "$INTS 0" synth --preset static --frames 2 --width 64 --height 48 --out "$O/synth" --quiet; done
# node / fuse (network: bad addresses and files fail before any connection)
NODE=(node --video "$F/cam1.avi" --connect-wait 0.2 --no-progress)
sweep_file "node --camera" yaml "$CAM_BAD" "${NODE[@]}" --camera @ --connect tcp://127.0.0.1:1
sweep_file "node --video" avi "$VIDEO_BAD" node --camera "$F/cam1.yaml" --video @ --connect tcp://127.0.0.1:1 --connect-wait 0.2 --no-progress
for v in "" "nonsense" "tcp://" "tcp://host:99999" "udp://127.0.0.1:5" "tcp://127.0.0.1:1"; do
  c "node --connect=$v" "connect" -- "${NODE[@]}" --camera "$F/cam1.yaml" --connect "$v"
done
for o in --ball-diameter --connect-wait --start-at --clock-offset; do sweep_opt node $o "nan inf 1e300 abc" "${NODE[@]}" --camera "$F/cam1.yaml" --connect tcp://127.0.0.1:1; done
sweep_opt node --live-buffer "$INTS 0" "${NODE[@]}" --camera "$F/cam1.yaml" --connect tcp://127.0.0.1:1
FUSE=(fuse --listen tcp://127.0.0.1:0 --idle-exit 0.5 --no-progress)
sweep_file "fuse --camera" yaml "${CAM_BAD/wrong_size/}" "${FUSE[@]}" --camera @ --camera "$F/cam2.yaml" --out "$OUTCSV"
sweep_out "fuse" "$F/cam1.yaml" "${FUSE[@]}" --camera "$F/cam1.yaml" --camera "$F/cam2.yaml" --out @
for v in "" "nonsense" "tcp://" "tcp://host:99999" "udp://127.0.0.1:5"; do
  c "fuse --listen=$v" "listen" -- fuse --listen "$v" --camera "$F/cam1.yaml" --camera "$F/cam2.yaml" --out "$O/new.csv" --no-progress --idle-exit 0.5
done
c "fuse --publish bad" "publish" -- "${FUSE[@]}" --camera "$F/cam1.yaml" --camera "$F/cam2.yaml" --out "$O/new.csv" --publish nonsense
for o in --idle-exit --tolerance --max-wait --ball-diameter --inlier-px; do sweep_opt fuse $o "nan inf 1e300 -1 abc" fuse --listen tcp://127.0.0.1:0 --camera "$F/cam1.yaml" --camera "$F/cam2.yaml" --out "$O/new.csv" --no-progress; done
# studio (starts a server only on good options: every case here must fail at once)
c "studio --port=99999" "port" -- studio --port 99999
c "studio --port=-1" "port" -- studio --port -1
c "studio --host=bogus" "host" -- studio --host "no such host" --port 0
c "studio --assets missing" "missing" -- studio --assets "$B/missing" --port 0
c "studio --assets=file" "empty.txt" -- studio --assets "$B/empty.txt" --port 0
# option errors
c "unknown subcommand" "bogus" quick -- bogus
c "unknown option" "--bogus" quick -- detect --bogus --video "$F/cam1.avi" --out "$O/new.csv"
c "missing required option" "--out" -- detect --video "$F/cam1.avi"
c "option without value" "--out" -- detect --video "$F/cam1.avi" --out

if [ $LIST = 1 ]; then echo "$nlisted cases"; exit 0; fi
echo "sweep: $((total - failed)) of $total cases held, $failed failed"
[ $failed = 0 ]
