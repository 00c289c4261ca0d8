# eval_scenario NAME [FRAMES]: the whole pipeline on a simulated scenario, scored for
# segmentation and camera trajectory; with ABLATION=1 also without segmentation
# feedback into SLAM; with FVB_ABLATION=1 also with the epipolar constraint alone (no
# Flow Vector Bound), scored for segmentation. Sourced by the sim-* evaluations.
source "$(dirname "${BASH_SOURCE[0]}")/_lib.sh"

eval_scenario() {
  local name="$1" frames="${2:-300}"
  local seq
  seq=$(sim_sequence "$name" "$frames")
  # The camera's mounting height above the ground (the simulated world's ground is z = 0):
  # what a robot's configuration holds; it gives the object filters metres per map unit.
  local cam_height
  cam_height=$(awk '!/^#/ && NF >= 8 {s += $4; n++} END {if (n) printf "%.3f", s / n; else print 0}' "$seq/cam_trajectory.tum")
  run_service "$seq/sequence.lcmlog" "$MBSLAM_EVAL_OUT/run" --set "objects.camera_height_m=$cam_height" ${SERVICE_ARGS:-}
  local ate ate_live="{}" ate_nf_live="{}" seg ate_nf="{}" seg_epi="{}" occ="{}" obj="{}" obj05="{}" rec="{}"
  ate=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$MBSLAM_EVAL_OUT/run/result/camera_trajectory.tum" \
        --gt-sequence "$seq" --plot "$MBSLAM_EVAL_OUT/trajectory.png")
  # The poses as published live (the trajectory file follows the later bundle adjustments).
  if [[ -s "$MBSLAM_EVAL_OUT/run/result/camera_trajectory_live.tum" ]]; then
    ate_live=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$MBSLAM_EVAL_OUT/run/result/camera_trajectory_live.tum" \
               --gt-sequence "$seq")
  fi
  seg=$(last_json "$MBSLAM_BIN/mbslam-eval-segmentation" --run "$MBSLAM_EVAL_OUT/run/out.lcmlog" --sequence "$seq" --name "$name")
  if [[ -f "$MBSLAM_EVAL_OUT/run/result/occupancy.bt" ]]; then
    occ=$(last_json "$MBSLAM_BIN/mbslam-eval-occupancy" --bt "$MBSLAM_EVAL_OUT/run/result/occupancy.bt" \
          --sequence "$seq" --est-traj "$MBSLAM_EVAL_OUT/run/result/camera_trajectory.tum" --pixel-step 4 --frame-step 5)
  fi
  if [[ "${OBJECTS:-1}" == "1" ]]; then
    obj=$(last_json "$MBSLAM_BIN/mbslam-eval" objects --est-log "$MBSLAM_EVAL_OUT/run/out.lcmlog" \
          --gt-log "$seq/sequence.lcmlog" --horizon-us 1000000 || echo "{}")
    obj05=$(last_json "$MBSLAM_BIN/mbslam-eval" objects --est-log "$MBSLAM_EVAL_OUT/run/out.lcmlog" \
          --gt-log "$seq/sequence.lcmlog" --horizon-us 500000 || echo "{}")
  fi
  # Moving objects' own reconstructions (object_slam): camera-relative trajectory and shape.
  if [[ -d "$MBSLAM_EVAL_OUT/run/result/reconstructions" ]]; then
    rec=$(last_json "$MBSLAM_BIN/mbslam-eval" reconstructions --dir "$MBSLAM_EVAL_OUT/run/result/reconstructions" \
          --gt-log "$seq/sequence.lcmlog" || echo "{}")
  fi
  if [[ "${ABLATION:-0}" == "1" ]]; then
    # The same options as the run it is compared with (SERVICE_ARGS), feedback off.
    run_service "$seq/sequence.lcmlog" "$MBSLAM_EVAL_OUT/no_feedback" --set "objects.camera_height_m=$cam_height" \
      ${SERVICE_ARGS:-} --set slam.use_segmentation=false
    ate_nf=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$MBSLAM_EVAL_OUT/no_feedback/result/camera_trajectory.tum" \
             --gt-sequence "$seq")
    if [[ -s "$MBSLAM_EVAL_OUT/no_feedback/result/camera_trajectory_live.tum" ]]; then
      ate_nf_live=$(last_json "$MBSLAM_BIN/mbslam-eval" ate \
                    --est "$MBSLAM_EVAL_OUT/no_feedback/result/camera_trajectory_live.tum" --gt-sequence "$seq")
    fi
  fi
  if [[ "${FVB_ABLATION:-0}" == "1" ]]; then
    # The same options, the Flow Vector Bound off: what the epipolar constraint alone finds.
    run_service "$seq/sequence.lcmlog" "$MBSLAM_EVAL_OUT/epipolar_only" --set "objects.camera_height_m=$cam_height" \
      ${SERVICE_ARGS:-} --set segmentation.likelihood.use_fvb=false
    seg_epi=$(last_json "$MBSLAM_BIN/mbslam-eval-segmentation" --run "$MBSLAM_EVAL_OUT/epipolar_only/out.lcmlog" \
              --sequence "$seq" --name "$name-epipolar-only")
  fi
  local len
  len=$(path_length "$seq/cam_trajectory.tum")
  python3 - "$name" "$ate" "$seg" "$ate_nf" "$len" "$MBSLAM_EVAL_OUT/run/result/summary.json" "$occ" "$obj" "$obj05" "$cam_height" "$rec" "$seg_epi" "$ate_live" "$ate_nf_live" <<'PY'
import json, sys
name, ate, seg, ate_nf, length = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3]), json.loads(sys.argv[4]), float(sys.argv[5])
summary = json.load(open(sys.argv[6]))
occ = json.loads(sys.argv[7])
obj = json.loads(sys.argv[8] or "{}")
obj05 = json.loads(sys.argv[9] or "{}")
objs = obj.get("objects", [])
rec = json.loads(sys.argv[11] or "{}")
seg_epi = json.loads(sys.argv[12] or "{}")
scales = [o["relative_scale_error"] for o in objs if o.get("settled_samples", 0) > 0]
rmse = ate.get("ate_rmse_m")
out = {"scenario": name, "path_length_m": length, "camera_height_m_given": float(sys.argv[10]),
       "ate_rmse_m": rmse, "ate_rel_path": rmse / length if (rmse is not None and length > 0) else None,
       "ate_rel_path_live": (json.loads(sys.argv[13] or "{}").get("ate_rmse_m") or 0) / length
                            if (json.loads(sys.argv[13] or "{}").get("ate_rmse_m") is not None and length > 0) else None,
       "tracked_fraction": ate.get("fraction_tracked"), "tracked_fraction_live": summary.get("tracked_fraction"),
       "sim3_scale": ate.get("scale"),
       "moving_recall": seg.get("moving_recall"), "moving_precision": seg.get("moving_precision"),
       "moving_recall_off_silhouette": seg.get("moving_recall_off_silhouette"),
       "moving_precision_off_silhouette": seg.get("moving_precision_off_silhouette"),
       "silhouette_px": seg.get("silhouette_px"),
       "false_moving_fraction": seg.get("false_moving_fraction"),
       "track_misclassification": seg.get("misclassification"),
       "detection_delay_frames": seg.get("detection_delay_frames"),
       "occupancy_precision": occ.get("occupancy_precision"), "occupancy_recall": occ.get("occupancy_recall"),
       "occupancy_voxel_m": occ.get("resolution_m"),
       "objects_estimated": obj.get("est_objects"), "objects_true": obj.get("gt_bodies"),
       "objects_matched": obj.get("matched"),
       "object_pos_err_rel_2s": obj.get("pos_err_rel_settled"),
       "relative_scale_error": (sum(scales) / len(scales)) if scales else None,
       "predicted_hit_rate_1s": obj.get("volume_hit_rate") if obj.get("volumes_checked") else None,
       "predicted_hit_rate_0_5s": obj05.get("volume_hit_rate") if obj05.get("volumes_checked") else None,
       "predicted_hit_rate_1s_all_estimates": obj.get("volume_hit_rate_all") if obj.get("volumes_checked_all") else None,
       "predicted_hit_rate_0_5s_all_estimates":
           obj05.get("volume_hit_rate_all") if obj05.get("volumes_checked_all") else None,
       "predicted_overlap_rate_1s_all_estimates":
           obj.get("volume_overlap_rate_all") if obj.get("volumes_checked_all") else None,
       "object_samples_matched_share": obj.get("matched_sample_share"),
       "object_samples_fragment_share": obj.get("fragment_sample_share"),
       "object_samples_phantom_share": obj.get("phantom_sample_share"),
       "predicted_volume_ratio_1s": obj.get("volume_ratio_median"),
       "predicted_volume_ratio_0_5s": obj05.get("volume_ratio_median"),
       "objects": [{k: o.get(k) for k in ("est_id", "name", "samples", "settled_samples", "pos_err_rel_settled_mean",
                                          "pos_err_rel_at_settle", "relative_scale_error", "volume_hit_rate",
                                          "volume_ratio_median")} for o in objs],
       "object_reconstructions": rec.get("reconstructions"),
       "object_traj_err_rel": rec.get("object_traj_err_rel"),
       "object_shape_err_rel": rec.get("object_shape_err_rel"),
       "object_shape_err_rel_median": rec.get("object_shape_err_rel_median"),
       "object_shape_translated_err_rel": rec.get("object_shape_translated_err_rel"),
       "object_reconstruction_images": rec.get("object_reconstruction_images"),
       "object_reconstruction_body": rec.get("object_reconstruction_body"),
       "timings_ms": {k: v.get("mean_ms") for k, v in summary.get("timings", {}).items()}}
if seg_epi:
    out["moving_recall_epipolar_only"] = seg_epi.get("moving_recall")
    out["moving_precision_epipolar_only"] = seg_epi.get("moving_precision")
    out["detection_delay_frames_epipolar_only"] = seg_epi.get("detection_delay_frames")
if ate_nf:
    out["ate_rel_path_no_feedback"] = ate_nf["ate_rmse_m"] / length if ("ate_rmse_m" in ate_nf and length > 0) else None
    ate_nf_live = json.loads(sys.argv[14] or "{}")
    out["ate_rel_path_no_feedback_live"] = (ate_nf_live["ate_rmse_m"] / length
                                            if ("ate_rmse_m" in ate_nf_live and length > 0) else None)
    out["tracked_fraction_no_feedback"] = ate_nf.get("fraction_tracked")
def pct(v):
    return "n/a" if v is None else f"{100*v:.3f} %"
print(f"sim-{name}: ATE {pct(out['ate_rel_path'])} of {length:.2f} m (live poses {pct(out['ate_rel_path_live'])}), tracked {pct(out['tracked_fraction'])} (live {pct(out['tracked_fraction_live'])}), "
      f"moving recall {out['moving_recall']}, precision {out['moving_precision']} ({out['moving_recall_off_silhouette']} / "
      f"{out['moving_precision_off_silhouette']} {out['silhouette_px']} px or more off the movers' silhouettes), false moving {out['false_moving_fraction']}")
if obj:
    print(f"  objects: {obj.get('est_objects')} estimated, {obj.get('matched')} matched of {obj.get('gt_bodies')}; "
          f"error/range from 2 s {out['object_pos_err_rel_2s']}, relative scale error {out['relative_scale_error']}, "
          f"volumes hit +0.5 s {out['predicted_hit_rate_0_5s']} +1 s {out['predicted_hit_rate_1s']} "
          f"(median size x the true box: {out['predicted_volume_ratio_0_5s']} / {out['predicted_volume_ratio_1s']})")
    print(f"  every estimate near a body: volumes hit +0.5 s {out['predicted_hit_rate_0_5s_all_estimates']} "
          f"+1 s {out['predicted_hit_rate_1s_all_estimates']} (+1 s volumes overlapping the true box "
          f"{out['predicted_overlap_rate_1s_all_estimates']}); object samples: matched "
          f"{out['object_samples_matched_share']}, fragments {out['object_samples_fragment_share']}, "
          f"phantoms {out['object_samples_phantom_share']}")
if rec.get("scored"):
    print(f"  reconstructions: {rec.get('reconstructions')} ({rec.get('scored')} scored); the longest "
          f"({rec.get('object_reconstruction_body')}, {rec.get('object_reconstruction_images')} images): camera-relative "
          f"trajectory {pct(rec.get('object_traj_err_rel'))} of its path, shape {pct(rec.get('object_shape_err_rel'))} "
          f"of the size (median {pct(rec.get('object_shape_err_rel_median'))}; "
          f"{pct(rec.get('object_shape_translated_err_rel'))} shifted onto the box)")
if occ:
    print(f"  occupancy: precision {occ.get('occupancy_precision')}, recall {occ.get('occupancy_recall')} (voxel {occ.get('resolution_m')} m)")
if ate_nf:
    print(f"  without segmentation feedback: ATE {pct(out.get('ate_rel_path_no_feedback'))} "
          f"(live poses {pct(out.get('ate_rel_path_no_feedback_live'))}), tracked {pct(out.get('tracked_fraction_no_feedback'))}")
if seg_epi:
    print(f"  epipolar constraint alone (no FVB): moving recall {out['moving_recall_epipolar_only']}, "
          f"precision {out['moving_precision_epipolar_only']}")
print(json.dumps(out))
PY
}
