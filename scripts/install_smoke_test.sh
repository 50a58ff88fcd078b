#!/usr/bin/env bash
# install_smoke_test.sh BUILD_DIR TMP_DIR: `cmake --install` into a prefix, moves the tree
# elsewhere (it must be relocatable) and runs the program from there: the codecs plugin, the model
# and the studio's front end must be found beside the installed program, not in the build.
set -euo pipefail
BUILD="$1"
TMP="$2"
SRC="$(cd "$(dirname "$0")/.." && pwd)"
fail() { echo "install_smoke: $*" >&2; exit 1; }
rm -rf "$TMP"
mkdir -p "$TMP"
cmake --install "$BUILD" --prefix "$TMP/stage" >"$TMP/install.log" || fail "cmake --install failed"
mv "$TMP/stage" "$TMP/moved"
P="$TMP/moved"
FV="$P/bin/fieldvision"
[ -x "$FV" ] || fail "no bin/fieldvision"
[ -f "$P/lib/fieldvision/libfieldvision_codecs.so" ] || fail "no lib/fieldvision plugin"
[ -f "$P/share/doc/fieldvision/README.md" ] || fail "no README"
"$FV" --version | grep -q '^fieldvision ' || fail "--version"

# The codecs plugin of the install (synth writes its videos through it).
unset FV_MODELS_DIR
"$FV" -v synth --preset static --frames 2 --width 160 --height 120 --out "$TMP/scene" --quiet \
  >"$TMP/synth.log" 2>&1 || fail "synth failed: $(tail -1 "$TMP/synth.log")"
grep -qF "codecs plugin: $P/lib/fieldvision/libfieldvision_codecs.so" "$TMP/synth.log" ||
  fail "the plugin was not loaded from the install: $(grep -F 'codecs plugin' "$TMP/synth.log")"

# The model, when the set-up made one.
if [ -f "$BUILD/models/nanodet.onnx" ]; then
  [ -f "$P/share/fieldvision/models/nanodet.onnx" ] || fail "model not installed"
  "$FV" -v detect --video "$TMP/scene/cam1.avi" --detector dnn --max-frames 1 --no-progress \
    --out "$TMP/det.csv" >"$TMP/detect.log" 2>&1 || fail "detect --detector dnn failed"
  grep -qF "model: $P/share/fieldvision/models/nanodet.onnx" "$TMP/detect.log" ||
    fail "the model was not found in the install: $(grep -F 'model:' "$TMP/detect.log")"
fi

# The studio's front end, when it was built.
if [ -f "$SRC/studio/dist/index.html" ]; then
  [ -f "$P/share/fieldvision/studio/index.html" ] || fail "studio front end not installed"
fi
echo "install_smoke: ok ($P)"
