#!/usr/bin/env bash
# Configures and builds mbslam. Usage: scripts/build.sh [BUILD_DIR] [extra cmake args...]
# Environment: BUILD_TYPE (default Release), JOBS (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
shift || true
build_type=${BUILD_TYPE:-Release}
jobs=${JOBS:-2}
werror=OFF
if [[ "${CI:-}" == "true" ]]; then werror=ON; fi
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="$build_type" -DMBSLAM_WERROR="$werror" "$@" >/dev/null
cmake --build "$build_dir" -j"$jobs"
