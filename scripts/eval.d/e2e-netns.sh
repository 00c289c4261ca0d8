#!/usr/bin/env bash
# End to end through real processes in a private network namespace: lcm-logplayer (real rate) -> perception_service (realtime) -> viewer, outputs recorded by lcm-logger; scored like the stage evaluations
#
#   scripts/eval.sh e2e-netns [SCENARIO] [FRAMES]     (default: multi 300)
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service)
#
# LCM's udpm:// multicast is used only inside the namespace (test/netns/run_in_netns.sh).
# The service runs live (drops stale frames and counts them), so its figures depend on
# the machine's load; the summary says how many frames it processed and dropped.
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
scenario="${1:-multi}"
frames="${2:-300}"
seq=$(sim_sequence "$scenario" "$frames")
out="$MBSLAM_EVAL_OUT"
rm -rf "$out/live"
mkdir -p "$out/live"
cam_height=$(awk '!/^#/ && NF >= 8 {s += $4; n++} END {if (n) printf "%.3f", s / n; else print 0}' "$seq/cam_trajectory.tum")

"$MBSLAM_ROOT/test/netns/run_in_netns.sh" bash -c '
  set -u
  bin="$1"; seq="$2"; live="$3"; root="$4"; cam_height="$5"; shift 5  # then the service options
  url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"  # 640x480 raw images: the default socket buffer holds less than one
  lcm-logger --lcm-url="$url" --quiet --channel="PERCEPTION_.*" "$live/outputs.lcmlog" 2>"$live/logger.log" &
  logger=$!
  "$bin/perception_service" --lcm-url "$url" --mode realtime --output-dir "$live/result" \
      --set "objects.camera_height_m=$cam_height" "$@" 2>"$live/service.log" &
  service=$!
  "$bin/viewer" --config "$root/config/viewer.yaml" --lcm-url "$url" --out "$live/snapshots" \
      --set viewer.log_level=warning --set viewer.snapshot_period_s=2.0 2>"$live/viewer.log" &
  viewer=$!
  sleep 2
  lcm-logplayer --lcm-url="$url" --speed=1 "$seq/sequence.lcmlog"
  sleep 3
  kill -INT "$service" "$viewer"
  wait "$service"; s=$?
  wait "$viewer"; v=$?
  kill -INT "$logger"; wait "$logger" || true
  echo "service exit $s, viewer exit $v" >&2
  [[ $s -eq 0 && $v -eq 0 ]]
' _ "$MBSLAM_BIN" "$seq" "$out/live" "$MBSLAM_ROOT" "$cam_height" ${SERVICE_ARGS:-}

ate=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$out/live/result/camera_trajectory.tum" --gt-sequence "$seq")
seg=$(last_json "$MBSLAM_BIN/mbslam-eval-segmentation" --run "$out/live/outputs.lcmlog" --sequence "$seq" --name "$scenario")
obj=$(last_json "$MBSLAM_BIN/mbslam-eval" objects --est-log "$out/live/outputs.lcmlog" --gt-log "$seq/sequence.lcmlog")
len=$(path_length "$seq/cam_trajectory.tum")
snapshots=$(find "$out/live/snapshots" -name '*.png' | wc -l)
python3 - "$scenario" "$ate" "$seg" "$obj" "$len" "$out/live/result/summary.json" "$snapshots" "$frames" <<'PY'
import json, sys
name, ate, seg, obj = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3]), json.loads(sys.argv[4])
length, summary, snapshots, frames = float(sys.argv[5]), json.load(open(sys.argv[6])), int(sys.argv[7]), int(sys.argv[8])
counters = summary.get("counters", {})
rmse = ate.get("ate_rmse_m")
out = {"scenario": name, "frames_sent": frames,
       "frames_processed": summary.get("frames"),
       "counters": counters,
       "ate_rel_path": rmse / length if (rmse is not None and length > 0) else None,
       "tracked_fraction": ate.get("fraction_tracked"), "tracked_fraction_live": summary.get("tracked_fraction"),
       "moving_recall": seg.get("moving_recall"), "moving_precision": seg.get("moving_precision"),
       "objects_matched": obj.get("matched"), "object_pos_err_rel_2s": obj.get("pos_err_rel_settled"),
       "predicted_hit_rate_1s": obj.get("volume_hit_rate") if obj.get("volumes_checked") else None,
       "snapshots": snapshots,
       "frame_total_p50_ms": summary.get("timings", {}).get("frame_total", {}).get("p50_ms"),
       "frame_total_p99_ms": summary.get("timings", {}).get("frame_total", {}).get("p99_ms")}
print(f"e2e-netns {name}: {out['frames_processed']} of {frames} frames processed live; ATE {out['ate_rel_path']} of path, "
      f"tracked {out['tracked_fraction']}; moving recall {out['moving_recall']} precision {out['moving_precision']}; "
      f"objects matched {out['objects_matched']}, error/range from 2 s {out['object_pos_err_rel_2s']}; {snapshots} snapshots")
print(json.dumps(out))
PY
