#!/usr/bin/env bash
# Soak: looped live replay for N minutes (default 20), RSS trend beyond the map's own memory; --asan: LeakSanitizer build
# Usage: scripts/eval.sh soak [MINUTES] [--asan] [--default-config] [--scenario NAME] [--set a.b=v ...]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service too)
# By default the map is held small (slam.max_keyframes=40, occupancy off) as in the
# slow soak test, so that a trend is a leak; --default-config runs the service's defaults
# (200 keyframes, local BA, occupancy: map growth shows in map_* and map_bounded).
# Under --asan the RSS slope is reported but not judged (ASan's quarantine keeps freed
# memory); the verdict is LeakSanitizer's.
# perception_service (realtime) is fed by camera_driver looping a simulated sequence over
# udpm:// inside a private network namespace (test/integration/soak.sh). --asan builds
# build-asan-soak/ with -DMBSLAM_SANITIZE=address (AddressSanitizer alone, LeakSanitizer
# report at exit; UBSan's abort-on-error would end a long run at the first finding).
# JSON: rss_start_mb, rss_end_mb, rss_slope_mb_per_min, rss_slope_beyond_map_mb_per_min,
# map_bounded, frames, asan, lsan_leaks, passed, ...
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
main() {  # read in full before it runs: editing the file during a run changes nothing
minutes=20
asan=0
extra=()
# Service options from the environment, as the other evaluations take them.
read -r -a service_env <<<"${SERVICE_ARGS:-}"
extra+=("${service_env[@]}")
bounded=(--set slam.max_keyframes=40 --set occupancy_enabled=false)
scenario=crossing
while [[ $# -gt 0 ]]; do
  case "$1" in
    --asan) asan=1; shift ;;
    --default-config) bounded=(); shift ;;
    --scenario) scenario="$2"; shift 2 ;;
    --set) extra+=(--set "$2"); shift 2 ;;
    [0-9]*) minutes="$1"; shift ;;
    *) echo "soak: unknown argument $1" >&2; echo '{}'; exit 2 ;;
  esac
done
build="$MBSLAM_BUILD"
if [[ "$asan" == 1 ]]; then
  build="$MBSLAM_ROOT/build-asan-soak"
  echo "building $build (AddressSanitizer alone: MBSLAM_SANITIZE=address) ..." >&2
  cmake -S "$MBSLAM_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMBSLAM_SANITIZE=address \
    -DMBSLAM_BUILD_TESTS=ON -DMBSLAM_BUILD_DRIVERS=ON -DMBSLAM_BUILD_TOOLS=ON -DMBSLAM_BUILD_BENCH=OFF \
    >"$MBSLAM_EVAL_OUT/asan_build.log" 2>&1
  cmake --build "$build" -j"${JOBS:-2}" --target perception_service camera_driver soak_monitor \
    >>"$MBSLAM_EVAL_OUT/asan_build.log" 2>&1 || {
    echo "soak: ASan build failed, see $MBSLAM_EVAL_OUT/asan_build.log" >&2
    echo '{}'
    exit 1
  }
fi
out="$MBSLAM_EVAL_OUT/run"
if [[ "$asan" == 1 ]]; then out+="_asan"; fi
if [[ ${#bounded[@]} == 0 ]]; then out+="_defaults"; fi
mkdir -p "$out"
# The input sequence from the release simulator (OSMesa under ASan is slow and noisy).
if [[ ! -f "$out/sequence/timestamps.txt" ]]; then
  "$MBSLAM_BIN/mbslam-sim" --quiet --scenario "$scenario" --size 320x240 --fps 30 --frames 300 \
    --depth png --out "$out/sequence" >"$out/sim.log" 2>&1
fi
rc=0
"$MBSLAM_ROOT/test/netns/run_in_netns.sh" "$MBSLAM_ROOT/test/integration/soak.sh" \
  "$build/bin" "$build/tests" "$minutes" "$out" --scenario "$scenario" "${bounded[@]}" "${extra[@]}" || rc=$?
if [[ "$rc" == 77 ]]; then
  echo "soak: no private network namespace here (unshare refused); not run"
  echo '{"skipped": "no network namespace"}'
fi
exit "$rc"
}
main "$@"
exit $?
