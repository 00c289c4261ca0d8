#!/usr/bin/env bash
# viewer: render time per snapshot (3D view at 1280x720 with 4x and without multisampling, image view), PNG writing, on a synthetic output log
#
# Usage: scripts/eval.sh viewer-speed [FRAMES]   (default 100 frames at 10 Hz, 640x480 images)
# Writes a synthetic log of the perception outputs (make_viewer_test_log, with bad
# messages mixed in), replays it through `viewer` on file://...?speed=0 with a snapshot
# every 0.5 s of message time, and reads viewer_stats.json. Last line: one JSON object.
set -euo pipefail
root="${MBSLAM_ROOT:-$(cd "$(dirname "$0")/../.." && pwd)}"
bin="${MBSLAM_BIN:-$root/build/bin}"
out="${MBSLAM_EVAL_OUT:-$root/out/eval/viewer-speed}"
frames="${1:-100}"
for tool in viewer make_viewer_test_log; do
  if [[ ! -x "$bin/$tool" ]]; then
    echo "viewer-speed: $bin/$tool not built" >&2
    exit 1
  fi
done
mkdir -p "$out"
log="$out/outputs.lcmlog"
"$bin/make_viewer_test_log" "$log" --frames "$frames" --faults 2>/dev/null >&2

run() {  # run NAME [viewer --set args...]
  local name="$1"
  shift
  rm -rf "$out/$name"
  "$bin/viewer" --config "$root/config/viewer.yaml" --lcm-url "file://$log?speed=0" --out "$out/$name" \
    --set viewer.snapshot_period_s=0.5 --set viewer.log_level=warning "$@" 2>"$out/$name.log" ||
    { echo "viewer-speed: viewer failed, see $out/$name.log" >&2; tail -5 "$out/$name.log" >&2; exit 1; }
}
run msaa4
run msaa1 --set view3d.antialias_samples=1
run top_down --set view3d.camera_mode=top_down

python3 - "$out" "$frames" <<'PY'
import json, sys
out, frames = sys.argv[1], int(sys.argv[2])
stats = {name: json.load(open(f"{out}/{name}/viewer_stats.json")) for name in ("msaa4", "msaa1", "top_down")}
s = stats["msaa4"]
r = {
    "frames": frames,
    "view3d_size": s["view3d_size"],
    "snapshots": s["snapshots_3d"],
    "view3d_first_ms": s["render_3d"]["first_ms"],
    "view3d_p50_ms": s["render_3d"]["p50_ms"],
    "view3d_p99_ms": s["render_3d"]["p99_ms"],
    "view3d_msaa1_first_ms": stats["msaa1"]["render_3d"]["first_ms"],
    "view3d_msaa1_p50_ms": stats["msaa1"]["render_3d"]["p50_ms"],
    "view3d_top_down_p50_ms": stats["top_down"]["render_3d"]["p50_ms"],
    "image_view_p50_ms": s["render_image"]["p50_ms"],
    "png_write_p50_ms": s["write_png"]["p50_ms"],
    "bad_messages": s["bad_messages_total"],
    "example_view3d": f"{out}/msaa4/view3d_latest.png",
    "example_image": f"{out}/msaa4/image_latest.png",
}
print(f"viewer-speed: {frames} frames, {r['snapshots']} snapshots of {r['view3d_size'][0]}x{r['view3d_size'][1]}")
print(f"  3D view, 4x MSAA: first {r['view3d_first_ms']:.1f} ms, then p50 {r['view3d_p50_ms']:.1f} ms, p99 {r['view3d_p99_ms']:.1f} ms")
print(f"  3D view, no MSAA: first {r['view3d_msaa1_first_ms']:.1f} ms, then p50 {r['view3d_msaa1_p50_ms']:.1f} ms")
print(f"  3D view top-down: p50 {r['view3d_top_down_p50_ms']:.1f} ms;  image view p50 {r['image_view_p50_ms']:.1f} ms;  PNG write p50 {r['png_write_p50_ms']:.1f} ms")
print(f"  bad messages counted: {r['bad_messages']};  snapshots: {r['example_view3d']}, {r['example_image']}")
print(json.dumps(r))
PY
