#!/usr/bin/env bash
# viewer: snapshots of the whole pipeline's outputs on a simulated scenario (lockstep service run + camera images), 3D follow / top-down and image views
#
# Usage: scripts/eval.sh viewer-sim [SCENARIO [FRAMES]]   (default: multi, 300 frames)
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service)
# Runs perception_service in lockstep on the cached simulator sequence, merges its output
# log with the sequence's camera images (merge_lcm_logs) and renders the result with
# `viewer` on file://...?speed=0: periodic snapshots every 2 s of message time in the
# follow view, and final ones in the top-down view. Last line: one JSON object.
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
scenario="${1:-multi}"
frames="${2:-300}"
for tool in viewer merge_lcm_logs perception_service mbslam-sim; do
  if [[ ! -x "$MBSLAM_BIN/$tool" ]]; then
    echo "viewer-sim: $MBSLAM_BIN/$tool not built" >&2
    exit 1
  fi
done
out="$MBSLAM_EVAL_OUT"
seq=$(sim_sequence "$scenario" "$frames")
run_service "$seq/sequence.lcmlog" "$out/run" ${SERVICE_ARGS:-}
"$MBSLAM_BIN/merge_lcm_logs" "$out/merged.lcmlog" "$seq/sequence.lcmlog" "$out/run/out.lcmlog" >&2

view() {  # view NAME [viewer --set args...]
  local name="$1"
  shift
  rm -rf "$out/$name"
  "$MBSLAM_BIN/viewer" --config "$MBSLAM_ROOT/config/viewer.yaml" \
    --lcm-url "file://$out/merged.lcmlog?speed=0" --out "$out/$name" \
    --set viewer.log_level=warning "$@" 2>"$out/$name.log" ||
    { echo "viewer-sim: viewer failed, see $out/$name.log" >&2; tail -5 "$out/$name.log" >&2; exit 1; }
}
view follow --set viewer.snapshot_period_s=2.0
view top_down --set viewer.snapshot_period_s=0 --set view3d.camera_mode=top_down

python3 - "$out" "$scenario" "$frames" <<'PY'
import json, sys
out, scenario, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])
f = json.load(open(f"{out}/follow/viewer_stats.json"))
t = json.load(open(f"{out}/top_down/viewer_stats.json"))
r = {
    "scenario": scenario, "frames": frames,
    "messages": f["messages"], "bad_messages": f["bad_messages_total"],
    "image_decode_errors": f["image_decode_errors"], "occupancy_decode_errors": f["occupancy_decode_errors"],
    "snapshots_3d": f["snapshots_3d"], "snapshots_image": f["snapshots_image"],
    "view3d_first_ms": f["render_3d"]["first_ms"], "view3d_p50_ms": f["render_3d"]["p50_ms"],
    "image_view_p50_ms": f["render_image"]["p50_ms"],
    "snapshot_follow": f"{out}/follow/view3d_latest.png",
    "snapshot_top_down": f"{out}/top_down/view3d_latest.png",
    "snapshot_image": f"{out}/follow/image_latest.png",
}
print(f"viewer-sim ({scenario}, {frames} frames): {sum(r['messages'].values())} messages, {r['bad_messages']} bad, "
      f"{r['snapshots_3d']} 3D and {r['snapshots_image']} image snapshots")
print(f"  3D view: first {r['view3d_first_ms']:.1f} ms, then p50 {r['view3d_p50_ms']:.1f} ms; image view p50 {r['image_view_p50_ms']:.1f} ms")
print(f"  {r['snapshot_follow']}\n  {r['snapshot_top_down']}\n  {r['snapshot_image']}")
print(json.dumps(r))
PY
