#!/usr/bin/env bash
# Installs every Debian package that curvesfm's build, tests, benchmarks and demo need.
# Safe to re-run: when everything is present it returns without touching apt.
# Run as root or through sudo (it re-invokes itself with sudo when needed).
set -euo pipefail

PACKAGES=(
  build-essential cmake git pkg-config
  libeigen3-dev
  libceres-dev libsuitesparse-dev libgoogle-glog-dev libgflags-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  libopencv-features2d-dev libopencv-flann-dev libopencv-calib3d-dev libopencv-video-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  opencv-doc
  python3 python3-numpy python3-matplotlib python3-plotly
  chromium
)

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root (need: ${missing[*]})" >&2; exit 1; }
  SUDO="sudo"
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
