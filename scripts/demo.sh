#!/usr/bin/env bash
# The main job on the embedded default: installs what is missing, builds (Release),
# makes a sample sequence, runs it end to end through the perception service and
# prints where the outputs are.
#
#   scripts/demo.sh [OUT_DIR]      (default out/demo)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
out="${1:-$root/out/demo}"
start=$(date +%s)

./scripts/install-deps.sh
echo "== building (Release)"
BUILD_TYPE=Release ./scripts/build.sh build >/dev/null
bin="$root/build/bin"
mkdir -p "$out"

echo "== sample sequence"
input="$out/input.lcmlog"
if [[ -x "$bin/mbslam-sim" ]]; then
  "$bin/mbslam-sim" --scenario multi --frames 150 --out "$out/sim" >"$out/sim.log" 2>&1
  input="$out/sim/sequence.lcmlog"
  echo "simulated multibody scene 'multi' (5 movers): $out/sim"
else
  "$root/build/tests/make_test_log" "$input" --frames 150 --width 640 --height 480
fi

echo "== perception_service (lockstep replay of $input)"
"$bin/perception_service" --lcm-url "file://$input?speed=0" --mode lockstep \
  --output-dir "$out/result" --output-log "$out/perception_output.lcmlog" \
  --set service.log_level=warning 2>"$out/perception.log"

snapshots=""
if [[ -x "$bin/viewer" && -x "$bin/merge_lcm_logs" ]]; then
  echo "== viewer (offscreen snapshots of the outputs over the camera images)"
  "$bin/merge_lcm_logs" "$out/merged.lcmlog" "$input" "$out/perception_output.lcmlog" >/dev/null
  "$bin/viewer" --config config/viewer.yaml --lcm-url "file://$out/merged.lcmlog?speed=0" \
    --out "$out/snapshots" --set viewer.log_level=warning --set viewer.snapshot_period_s=2.0 \
    2>"$out/viewer.log"
  snapshots="$out/snapshots"
fi

echo "== outputs"
echo "camera trajectory : $out/result/camera_trajectory.tum"
echo "object tracks     : $out/result/objects/"
echo "static map        : $out/result/map.ply"
echo "run summary       : $out/result/summary.json"
echo "output log        : $out/perception_output.lcmlog (PERCEPTION_* channels, replay with lcm-logplayer)"
echo "service log       : $out/perception.log"
if [[ -n "$snapshots" ]]; then
  echo "snapshots         : $snapshots/view3d_latest.png, $snapshots/image_latest.png"
fi
cat "$out/result/summary.json"
echo "demo finished in $(( $(date +%s) - start )) s"
