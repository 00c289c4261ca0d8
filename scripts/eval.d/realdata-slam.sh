#!/usr/bin/env bash
# Real sequences for the camera trajectory (issue SLAM item 5): TartanAir indoor (189 continuous low-texture frames) and TUM fr3 cabinet (58 wide-baseline frames); tracked fraction (trajectory file, with back-filled poses, as the simulated scenes count it), live tracked fraction, ATE
#
#   scripts/eval.sh realdata-slam [--sequences "tartanair tum-cabinet"] [--starts "0 8 16 24 40"]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service)
#
# camera_driver turns the dataset folder (../shared/data, or MBSLAM_DATA) into an LCM log
# with its calibration and ground truth, the service replays it in lockstep, mbslam-eval
# scores the trajectory file against the truth (Sim(3) alignment: monocular).
# --starts (TartanAir only): the sequence is also replayed from these start images (its
# images and truth shifted), because one lost track changes every later decision of
# this sequence: a change is judged on the mean over starts, not on one replay.
# JSON (last line): {"tartanair": {"frames", "tracked_fraction" (images with a pose in the
#   trajectory file / images: the file ATE scores, and what the simulated scenes'
#   tracked_fraction counts), "tracked_fraction_live" (images posed when they were
#   processed / images: a monocular map starts only after the first pair with enough
#   parallax), "posed_fraction" (= tracked_fraction, the former name), "ate_rmse_m", "ate_rel_path",
#   "path_length_m" (all of the first start), "ate_rel_path_live" (the poses as published
#   live, without the later bundle adjustments the trajectory file follows),
#   "static_false_moving_fraction", "static_frames_with_moving_share", "static_phantom_objects"
#   (both scenes are static: the share of the scored features labelled moving, of the
#   images with any, and the objects, all false; mbslam-eval-realdata static); with several
#   starts also "starts" (the same keys per start) and "tracked_fraction_mean",
#   "tracked_fraction_live_mean", "posed_fraction_mean", "ate_rel_path_mean", "ate_rel_path_live_mean",
#   "static_false_moving_fraction_mean", "static_frames_with_moving_share_mean", "static_phantom_objects_mean",
#   "ate_rel_path_median"}, "tum-cabinet": {...}}
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
sequences="tartanair tum-cabinet"
starts="0"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sequences) sequences="$2"; shift 2 ;;
    --starts) starts="$2"; shift 2 ;;
    *) echo "realdata-slam: unknown argument $1" >&2; echo '{}'; exit 2 ;;
  esac
done
for k in $starts; do
  if ! [[ "$k" =~ ^[0-9]+$ ]]; then echo "realdata-slam: --starts takes image indices, not '$k'" >&2; echo '{}'; exit 2; fi
done
out="$MBSLAM_EVAL_OUT"
mkdir -p "$out"

# run_one NAME DATA DIR -> prints the JSON object of one replay
run_one() {
  local name="$1" data="$2" dir="$3" source_kind calib rate truth c1 c2 c3
  case "$name" in
    tartanair)
      source_kind=tartanair; calib=config/camera/tartanair.yaml; rate=10
      truth="$data/pose_left.txt"; c1=1; c2=2; c3=3 ;;
    tum-cabinet)
      source_kind=tum; calib=config/camera/tum_fr3.yaml; rate=0
      truth="$data/truth_cam_poses.txt"; c1=2; c2=3; c3=4 ;;
  esac
  mkdir -p "$dir"
  local log="$dir/camera.lcmlog"
  local rate_args=()
  if [[ "$rate" != 0 ]]; then rate_args=(--rate "$rate"); fi
  "$MBSLAM_BIN/camera_driver" --source "$source_kind" --input "$data" "${rate_args[@]}" \
    --calibration "$MBSLAM_ROOT/$calib" --log "$log" --quiet --no-progress --log-level warning >&2
  run_service "$log" "$dir/run" ${SERVICE_ARGS:-}
  local ate ate_live="{}" length static
  # Both scenes are static: every moving label is false, every object a phantom.
  static=$(last_json "$MBSLAM_BIN/mbslam-eval-realdata" static --run "$dir/run/out.lcmlog" --name "$name")
  ate=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$dir/run/result/camera_trajectory.tum" --gt-log "$log" \
        --plot "$dir/trajectory.png")
  if [[ -s "$dir/run/result/camera_trajectory_live.tum" ]]; then
    ate_live=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$dir/run/result/camera_trajectory_live.tum" --gt-log "$log")
  fi
  length=$(awk -v a="$c1" -v b="$c2" -v c="$c3" '!/^#/ && NF >= 7 {
             if (n++) {dx = $a - x; dy = $b - y; dz = $c - z; L += sqrt(dx*dx + dy*dy + dz*dz)}
             x = $a; y = $b; z = $c} END {printf "%.6f\n", L}' "$truth")
  python3 - "$name" "$dir/run/result/summary.json" "$length" "$ate" "$ate_live" "$static" <<'PY'
import json, sys
name, summary_path, length, ate = sys.argv[1], sys.argv[2], float(sys.argv[3]), json.loads(sys.argv[4] or "{}")
ate_live = json.loads(sys.argv[5] or "{}")
static = json.loads(sys.argv[6] or "{}")
s = json.load(open(summary_path))
rmse = ate.get("ate_rmse_m")
# The file's share of the images, as mbslam-eval counts it for the simulated scenes (the
# service's own count of the file, posed_fraction, when no ATE could be computed).
scored = ate.get("fraction_tracked")
posed = round(scored if scored is not None else s.get("posed_fraction", 0.0), 4)
r = {"frames": s["frames"], "tracked_fraction": posed, "tracked_fraction_live": round(s["tracked_fraction"], 4),
     "posed_fraction": posed,
     "ate_rmse_m": rmse, "path_length_m": round(length, 3),
     "ate_rel_path": None if rmse is None or length <= 0 else rmse / length,
     "trajectory_fraction_scored": ate.get("fraction_tracked")}
rmse_live = ate_live.get("ate_rmse_m")
r["ate_rel_path_live"] = None if rmse_live is None or length <= 0 else rmse_live / length
r["static_false_moving_fraction"] = static.get("static_false_moving_fraction")
r["static_frames_with_moving_share"] = static.get("static_frames_with_moving_share")
r["static_phantom_objects"] = static.get("static_phantom_objects")
print(f"{name}: {s['frames']} images, tracked (trajectory file) {100 * r['tracked_fraction']:.1f} %, live poses "
      f"{100 * r['tracked_fraction_live']:.1f} %, ATE {rmse} m = "
      f"{'n/a' if r['ate_rel_path'] is None else round(100 * r['ate_rel_path'], 2)} % of the {length:.2f} m path; "
      f"static scene: {r['static_false_moving_fraction']} of the features labelled moving, "
      f"{r['static_phantom_objects']} phantom objects", file=sys.stderr)
print(json.dumps(r))
PY
}

results=()
for name in $sequences; do
  case "$name" in
    tartanair) data="$MBSLAM_DATA/tartanair_indoor_subset" ;;
    tum-cabinet) data="$MBSLAM_DATA/tum_fr3_cabinet_subset" ;;
    *) echo "realdata-slam: unknown sequence $name" >&2; continue ;;
  esac
  if [[ ! -d "$data" ]]; then
    echo "realdata-slam: $data missing, $name skipped" >&2
    continue
  fi
  if [[ "$name" != tartanair || "$starts" == "0" ]]; then
    results+=("{\"$name\": $(run_one "$name" "$data" "$out/$name")}")
    continue
  fi
  per_start=()
  for k in $starts; do
    if [[ "$k" == 0 ]]; then
      dir="$out/$name"; shifted="$data"
    else
      dir="$out/$name-from$k"; shifted="$out/data-$name-from$k"
      tartanair_from "$k" "$data" "$shifted"
    fi
    echo "realdata-slam: $name from image $k" >&2
    per_start+=("$k" "$(run_one "$name" "$shifted" "$dir")")
  done
  results+=("$(python3 - "$name" "${per_start[@]}" <<'PY'
import json, statistics, sys
name, rest = sys.argv[1], sys.argv[2:]
runs = {int(rest[i]): json.loads(rest[i + 1]) for i in range(0, len(rest), 2)}
first = runs[min(runs)] if 0 not in runs else runs[0]
out = dict(first)
out["starts"] = {str(k): v for k, v in runs.items()}
for key in ("tracked_fraction", "tracked_fraction_live", "posed_fraction", "ate_rel_path", "ate_rel_path_live",
            "static_false_moving_fraction", "static_frames_with_moving_share", "static_phantom_objects"):
    vals = [v[key] for v in runs.values() if v.get(key) is not None]
    out[key + "_mean"] = statistics.mean(vals) if vals else None
def fmt(x, scale, spec, unit):
    return "n/a" if x is None else f"{scale * x:{spec}}{unit}"
vals = [v["ate_rel_path"] for v in runs.values() if v.get("ate_rel_path") is not None]
out["ate_rel_path_median"] = statistics.median(vals) if vals else None
print(f"{name} over starts {sorted(runs)}: tracked (trajectory file) {100 * out['tracked_fraction_mean']:.1f} %, live poses "
      f"{100 * out['tracked_fraction_live_mean']:.1f} %, ATE mean {100 * out['ate_rel_path_mean']:.2f} % "
      f"(median {100 * out['ate_rel_path_median']:.2f} %) of the path; static scene: "
      f"{fmt(out['static_false_moving_fraction_mean'], 100, '.1f', ' %')} of the features labelled moving, in "
      f"{fmt(out['static_frames_with_moving_share_mean'], 100, '.0f', ' %')} of the images, "
      f"{fmt(out['static_phantom_objects_mean'], 1, '.1f', '')} phantom objects (means)", file=sys.stderr)
print(json.dumps({name: out}))
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
