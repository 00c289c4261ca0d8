#!/usr/bin/env bash
# The main job on the embedded default: installs what is missing, builds (Release),
# makes a sample sequence (simulated multibody scene) and, when ../shared/data is there,
# a real one; runs each end to end (camera_driver -> perception_service -> viewer) and
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

# run_one NAME INPUT_LOG [perception_service args...]: lockstep replay, then viewer snapshots
# of the outputs over the camera images; everything under $out/NAME.
run_one() {
  local name="$1" input="$2"
  shift 2
  local dir="$out/$name"
  mkdir -p "$dir"
  echo "== perception_service ($name: lockstep replay of $input)"
  "$bin/perception_service" --lcm-url "file://$input?speed=0" --mode lockstep \
    --output-dir "$dir/result" --output-log "$dir/perception_output.lcmlog" \
    --set service.log_level=warning "$@" 2>"$dir/perception.log"
  if [[ -x "$bin/viewer" && -x "$bin/merge_lcm_logs" ]]; then
    echo "== viewer ($name: offscreen snapshots of the outputs over the camera images)"
    "$bin/merge_lcm_logs" "$dir/merged.lcmlog" "$input" "$dir/perception_output.lcmlog" >/dev/null
    "$bin/viewer" --config config/viewer.yaml --lcm-url "file://$dir/merged.lcmlog?speed=0" \
      --out "$dir/snapshots" --set viewer.log_level=warning --set viewer.snapshot_period_s=2.0 \
      2>"$dir/viewer.log"
  fi
  echo "-- outputs of $name"
  echo "camera trajectory : $dir/result/camera_trajectory.tum"
  echo "object tracks     : $dir/result/objects/"
  echo "static map        : $dir/result/map.ply"
  echo "occupancy (OctoMap): $dir/result/occupancy.bt"
  echo "run summary       : $dir/result/summary.json"
  echo "output log        : $dir/perception_output.lcmlog (PERCEPTION_* channels, replay with lcm-logplayer)"
  echo "service log       : $dir/perception.log"
  if [[ -d "$dir/snapshots" ]]; then
    echo "snapshots         : $dir/snapshots/view3d_latest.png, $dir/snapshots/image_latest.png"
  fi
  python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); print("summary           : %d frames, %.1f %% tracked, %d map points, %d occupied voxels, %d objects with a trajectory" % (s["frames"], 100 * s["tracked_fraction"], s["map_points"], s["occupied_voxels"], s["objects_with_trajectory"]))' "$dir/result/summary.json"
}

# 1. A simulated multibody scene: the simulator renders the images, camera_driver turns
#    them into an LCM log (as it would publish a live camera), the service runs on it.
echo "== sample sequence: simulated multibody scene 'multi' (5 movers)"
"$bin/mbslam-sim" --scenario multi --frames 150 --out "$out/sim" >"$out/sim.log" 2>&1
"$bin/camera_driver" --source sequence --input "$out/sim" --log "$out/sim_camera.lcmlog" --quiet \
  --no-progress --log-level warning
cam_height=$(awk '!/^#/ && NF >= 8 {s += $4; n++} END {if (n) printf "%.3f", s / n; else print 1.6}' "$out/sim/cam_trajectory.tum")
run_one sim-multi "$out/sim_camera.lcmlog" --set "objects.camera_height_m=$cam_height"
if [[ -x "$bin/mbslam-eval" ]]; then
  "$bin/mbslam-eval" ate --est "$out/sim-multi/result/camera_trajectory.tum" --gt-sequence "$out/sim" 2>&1 |
    grep -E 'poses:|ATE translation' | sed 's/^ */accuracy          : /' || true
fi

# 2. A real sequence from ../shared/data when it is there (TartanAir indoor, 640x480).
data="${MBSLAM_DATA:-$root/../shared/data}"
if [[ -d "$data/tartanair_indoor_subset" ]]; then
  echo "== real sequence: TartanAir indoor subset ($data/tartanair_indoor_subset)"
  "$bin/camera_driver" --source tartanair --input "$data/tartanair_indoor_subset" --rate 10 \
    --calibration config/camera/tartanair.yaml --log "$out/tartanair_camera.lcmlog" --quiet \
    --no-progress --log-level warning
  run_one tartanair "$out/tartanair_camera.lcmlog"
  if [[ -x "$bin/mbslam-eval" ]]; then
    "$bin/mbslam-eval" ate --est "$out/tartanair/result/camera_trajectory.tum" \
      --gt-log "$out/tartanair_camera.lcmlog" 2>&1 |
      grep -E 'poses:|ATE translation' | sed 's/^ */accuracy          : /' || true
  fi
else
  echo "(no ../shared/data/tartanair_indoor_subset: the real-sequence part is skipped)"
fi
echo "demo finished in $(( $(date +%s) - start )) s"
