#!/usr/bin/env bash
# Installs every Debian 12 package mbslam needs. Idempotent: when everything is
# present it only runs dpkg-query and returns in about a second.
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake pkg-config git
  # messaging
  liblcm-dev liblcm-bin libglib2.0-dev
  # math / vision / optimisation / mapping
  libeigen3-dev libopencv-dev opencv-data libceres-dev liboctomap-dev libyaml-cpp-dev
  # sensors and middleware
  libdc1394-dev libfastrtps-dev libfastcdr-dev fastddsgen default-jre-headless
  # offscreen rendering
  libosmesa6-dev
  # tests, benchmarks, fuzzing, sanitizers
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  # evaluation scripts (JSON assembly)
  python3
  # network namespaces for the udpm:// tests
  iproute2 util-linux
)

missing=()
for p in "${PACKAGES[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
# Refresh the package lists only when an install fails on stale lists.
if ! $SUDO apt-get install -y --no-install-recommends "${missing[@]}"; then
  $SUDO apt-get update
  $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi
echo "install-deps: done"
