#!/usr/bin/env bash
# Scenario 'robot_odometry': metric scale from wheel odometry (scale error), camera ATE, segmentation
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
frames="${1:-300}"
seq=$(sim_sequence robot_odometry "$frames")
# The camera-robot extrinsic the simulator used (what a calibration would give).
t=$(sed -n 's/^translation: *\[\([^]]*\)\].*/\1/p' "$seq/extrinsic.yaml" | tr -d ' ')
q=$(sed -n 's/^quaternion: *\[\([^]]*\)\].*/\1/p' "$seq/extrinsic.yaml" | tr -d ' ')
run_service "$seq/sequence.lcmlog" "$MBSLAM_EVAL_OUT/run" \
  --set "odometry.base_from_cam_translation=[$t]" --set "odometry.base_from_cam_rotation=[$q]" ${SERVICE_ARGS:-}
ate=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$MBSLAM_EVAL_OUT/run/result/camera_trajectory.tum" \
      --gt-sequence "$seq" --plot "$MBSLAM_EVAL_OUT/trajectory.png")
ate_se3=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$MBSLAM_EVAL_OUT/run/result/camera_trajectory.tum" \
      --gt-sequence "$seq" --align se3)
seg=$(last_json "$MBSLAM_BIN/mbslam-eval-segmentation" --run "$MBSLAM_EVAL_OUT/run/out.lcmlog" --sequence "$seq" \
      --name robot_odometry || echo "{}")
len=$(path_length "$seq/cam_trajectory.tum")
python3 - "$ate" "$ate_se3" "$len" "$seg" "$MBSLAM_EVAL_OUT/run/result/summary.json" <<'PY'
import json, sys
ate, se3, length = json.loads(sys.argv[1]), json.loads(sys.argv[2]), float(sys.argv[3])
seg = json.loads(sys.argv[4] or "{}")
summary = json.load(open(sys.argv[5]))
scale = ate.get("scale")
out = {"scenario": "robot_odometry", "path_length_m": length,
       "scale_error": abs(scale - 1.0) if scale else None, "sim3_scale": scale,
       "ate_rel_path": ate["ate_rmse_m"] / length, "ate_se3_rmse_m": se3["ate_rmse_m"],
       "tracked_fraction": ate.get("fraction_tracked"), "tracked_fraction_live": summary.get("tracked_fraction"),
       "moving_recall": seg.get("moving_recall"), "moving_precision": seg.get("moving_precision"),
       "moving_recall_off_silhouette": seg.get("moving_recall_off_silhouette"),
       "moving_precision_off_silhouette": seg.get("moving_precision_off_silhouette"),
       "silhouette_px": seg.get("silhouette_px"),
       "false_moving_fraction": seg.get("false_moving_fraction")}
print(f"sim-robot_odometry: metric scale error {100*out['scale_error']:.2f} %, ATE (Sim3) {100*out['ate_rel_path']:.3f} % of {length:.2f} m, "
      f"ATE (SE3, metric) {se3['ate_rmse_m']:.4f} m, tracked {100*out['tracked_fraction']:.1f} % (live {100*out['tracked_fraction_live']:.1f} %); moving recall "
      f"{out['moving_recall']}, precision {out['moving_precision']}, false moving {out['false_moving_fraction']}")
print(json.dumps(out))
PY
