#!/usr/bin/env bash
# Real sequences for the camera trajectory (issue SLAM item 5): TartanAir indoor (189 continuous low-texture frames) and TUM fr3 cabinet (58 wide-baseline frames); live tracked fraction, trajectory-file fraction (with back-filled poses), ATE
#
#   scripts/eval.sh realdata-slam [--sequences "tartanair tum-cabinet"]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service)
#
# camera_driver turns the dataset folder (../shared/data, or MBSLAM_DATA) into an LCM log
# with its calibration and ground truth, the service replays it in lockstep, mbslam-eval
# scores the trajectory file against the truth (Sim(3) alignment: monocular).
# JSON (last line): {"tartanair": {"frames", "tracked_fraction" (live poses / images),
#   "posed_fraction" (trajectory file / images), "ate_rmse_m", "ate_rel_path",
#   "path_length_m"}, "tum-cabinet": {...}}
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
sequences="tartanair tum-cabinet"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sequences) sequences="$2"; shift 2 ;;
    *) echo "realdata-slam: unknown argument $1" >&2; echo '{}'; exit 2 ;;
  esac
done
out="$MBSLAM_EVAL_OUT"
mkdir -p "$out"
results=()
for name in $sequences; do
  case "$name" in
    tartanair)
      data="$MBSLAM_DATA/tartanair_indoor_subset"; source_kind=tartanair; calib=config/camera/tartanair.yaml; rate=10
      truth="$data/pose_left.txt"; c1=1; c2=2; c3=3 ;;
    tum-cabinet)
      data="$MBSLAM_DATA/tum_fr3_cabinet_subset"; source_kind=tum; calib=config/camera/tum_fr3.yaml; rate=0
      truth="$data/truth_cam_poses.txt"; c1=2; c2=3; c3=4 ;;
    *) echo "realdata-slam: unknown sequence $name" >&2; continue ;;
  esac
  if [[ ! -d "$data" ]]; then
    echo "realdata-slam: $data missing, $name skipped" >&2
    continue
  fi
  dir="$out/$name"
  mkdir -p "$dir"
  log="$dir/camera.lcmlog"
  rate_args=()
  if [[ "$rate" != 0 ]]; then rate_args=(--rate "$rate"); fi
  "$MBSLAM_BIN/camera_driver" --source "$source_kind" --input "$data" "${rate_args[@]}" \
    --calibration "$MBSLAM_ROOT/$calib" --log "$log" --quiet --no-progress --log-level warning >&2
  run_service "$log" "$dir/run" ${SERVICE_ARGS:-}
  ate=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$dir/run/result/camera_trajectory.tum" --gt-log "$log" \
        --plot "$dir/trajectory.png")
  length=$(awk -v a="$c1" -v b="$c2" -v c="$c3" '!/^#/ && NF >= 7 {
             if (n++) {dx = $a - x; dy = $b - y; dz = $c - z; L += sqrt(dx*dx + dy*dy + dz*dz)}
             x = $a; y = $b; z = $c} END {printf "%.6f\n", L}' "$truth")
  results+=("$(python3 - "$name" "$dir/run/result/summary.json" "$length" "$ate" <<'PY'
import json, sys
name, summary_path, length, ate = sys.argv[1], sys.argv[2], float(sys.argv[3]), json.loads(sys.argv[4] or "{}")
s = json.load(open(summary_path))
rmse = ate.get("ate_rmse_m")
r = {"frames": s["frames"], "tracked_fraction": round(s["tracked_fraction"], 4),
     "posed_fraction": round(s.get("posed_fraction", s["tracked_fraction"]), 4),
     "ate_rmse_m": rmse, "path_length_m": round(length, 3),
     "ate_rel_path": None if rmse is None or length <= 0 else rmse / length,
     "trajectory_fraction_scored": ate.get("fraction_tracked")}
print(f"{name}: {s['frames']} images, live poses {100 * r['tracked_fraction']:.1f} %, trajectory file "
      f"{100 * r['posed_fraction']:.1f} %, ATE {rmse} m = "
      f"{'n/a' if r['ate_rel_path'] is None else round(100 * r['ate_rel_path'], 2)} % of the {length:.2f} m path",
      file=sys.stderr)
print(json.dumps({name: r}))
PY
)")
done
python3 - "${results[@]}" <<'PY'
import json, sys
out = {}
for a in sys.argv[1:]:
    out.update(json.loads(a))
print(json.dumps(out))
PY
