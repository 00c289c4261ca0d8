# eval_scenario NAME [FRAMES]: the whole pipeline on a simulated scenario, scored for
# segmentation and camera trajectory; with ABLATION=1 also without segmentation
# feedback into SLAM. Sourced by the sim-* evaluations.
source "$(dirname "${BASH_SOURCE[0]}")/_lib.sh"

eval_scenario() {
  local name="$1" frames="${2:-300}"
  local seq
  seq=$(sim_sequence "$name" "$frames")
  run_service "$seq/sequence.lcmlog" "$MBSLAM_EVAL_OUT/run"
  local ate seg ate_nf="{}" occ="{}"
  ate=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$MBSLAM_EVAL_OUT/run/result/camera_trajectory.tum" \
        --gt-sequence "$seq" --plot "$MBSLAM_EVAL_OUT/trajectory.png")
  seg=$(last_json "$MBSLAM_BIN/mbslam-eval-segmentation" --run "$MBSLAM_EVAL_OUT/run/out.lcmlog" --sequence "$seq" --name "$name")
  if [[ -f "$MBSLAM_EVAL_OUT/run/result/occupancy.bt" ]]; then
    occ=$(last_json "$MBSLAM_BIN/mbslam-eval-occupancy" --bt "$MBSLAM_EVAL_OUT/run/result/occupancy.bt" \
          --sequence "$seq" --est-traj "$MBSLAM_EVAL_OUT/run/result/camera_trajectory.tum" --pixel-step 4 --frame-step 5)
  fi
  if [[ "${ABLATION:-0}" == "1" ]]; then
    run_service "$seq/sequence.lcmlog" "$MBSLAM_EVAL_OUT/no_feedback" --set slam.use_segmentation=false
    ate_nf=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$MBSLAM_EVAL_OUT/no_feedback/result/camera_trajectory.tum" \
             --gt-sequence "$seq")
  fi
  local len
  len=$(path_length "$seq/cam_trajectory.tum")
  python3 - "$name" "$ate" "$seg" "$ate_nf" "$len" "$MBSLAM_EVAL_OUT/run/result/summary.json" "$occ" <<'PY'
import json, sys
name, ate, seg, ate_nf, length = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3]), json.loads(sys.argv[4]), float(sys.argv[5])
summary = json.load(open(sys.argv[6]))
occ = json.loads(sys.argv[7])
rmse = ate.get("ate_rmse_m")
out = {"scenario": name, "path_length_m": length,
       "ate_rmse_m": rmse, "ate_rel_path": rmse / length if (rmse is not None and length > 0) else None,
       "tracked_fraction": ate.get("fraction_tracked"), "sim3_scale": ate.get("scale"),
       "moving_recall": seg.get("moving_recall"), "moving_precision": seg.get("moving_precision"),
       "false_moving_fraction": seg.get("false_moving_fraction"),
       "track_misclassification": seg.get("misclassification"),
       "detection_delay_frames": seg.get("detection_delay_frames"),
       "occupancy_precision": occ.get("occupancy_precision"), "occupancy_recall": occ.get("occupancy_recall"),
       "occupancy_voxel_m": occ.get("resolution_m"),
       "timings_ms": {k: v.get("mean_ms") for k, v in summary.get("timings", {}).items()}}
if ate_nf:
    out["ate_rel_path_no_feedback"] = ate_nf["ate_rmse_m"] / length if ("ate_rmse_m" in ate_nf and length > 0) else None
    out["tracked_fraction_no_feedback"] = ate_nf.get("fraction_tracked")
def pct(v):
    return "n/a" if v is None else f"{100*v:.3f} %"
print(f"sim-{name}: ATE {pct(out['ate_rel_path'])} of {length:.2f} m, tracked {pct(out['tracked_fraction'])}, "
      f"moving recall {out['moving_recall']}, precision {out['moving_precision']}, false moving {out['false_moving_fraction']}")
if occ:
    print(f"  occupancy: precision {occ.get('occupancy_precision')}, recall {occ.get('occupancy_recall')} (voxel {occ.get('resolution_m')} m)")
if ate_nf:
    print(f"  without segmentation feedback: ATE {pct(out.get('ate_rel_path_no_feedback'))}, tracked {pct(out.get('tracked_fraction_no_feedback'))}")
print(json.dumps(out))
PY
}
