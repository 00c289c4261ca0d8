#!/usr/bin/env bash
# DAVIS 2016 (10 sequences, real video): moving-feature precision / recall and region IoU (J) per sequence and mean
#
#   scripts/eval.sh davis [--rate HZ] [--calibration YAML] [--sequences a,b] [perception_service args...]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service too)
#
# Each sequence's JPEG folder becomes an LCM log (camera_driver, folder source, nominal
# time stamps at --rate, default 24 Hz: DAVIS 2016 was captured at 24 fps), the service
# replays it lockstep, and mbslam-eval-realdata scores PERCEPTION_TRACKS / PERCEPTION_OBJECTS
# against Annotations/<seq>/*.png. DAVIS is uncalibrated: the default intrinsics are a guess
# (config/camera/davis_854x480.yaml: focal = image width = 854 px, principal point at the
# centre, no distortion). Outputs: $MBSLAM_EVAL_OUT/{logs,runs/<seq>,per_frame}.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/_lib.sh"
root="${MBSLAM_DATA}/davis2016"
if [[ ! -d "$root/Annotations" ]]; then
  echo "davis: $root not found (set MBSLAM_DATA)"; echo '{"skipped": true}'; exit 0
fi
rate=24
calib="$MBSLAM_ROOT/config/camera/davis_854x480.yaml"
sequences=""
service_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --rate) rate="$2"; shift 2 ;;
    --calibration) calib="$2"; shift 2 ;;
    --sequences) sequences="$2"; shift 2 ;;
    *) service_args+=("$1"); shift ;;
  esac
done
# SERVICE_ARGS="--set a.b=v ..." (as the other evaluations take it) adds to them.
read -r -a env_args <<< "${SERVICE_ARGS:-}"
service_args+=(${env_args[@]+"${env_args[@]}"})
out="$MBSLAM_EVAL_OUT"
mkdir -p "$out/logs" "$out/runs"
names=()
for d in "$root"/Annotations/*/; do
  name=$(basename "$d")
  if [[ -n "$sequences" && ",$sequences," != *",$name,"* ]]; then continue; fi
  names+=("$name")
done
echo "davis: ${#names[@]} sequences at ${rate} Hz, intrinsics $(basename "$calib") (approximate: focal = width, centred principal point)"
for name in "${names[@]}"; do
  log="$out/logs/$name.lcmlog"
  "$MBSLAM_BIN/camera_driver" --source folder --input "$root/JPEGImages/$name" --rate "$rate" \
    --calibration "$calib" --encoding source --log "$log" >"$out/logs/$name.driver.log" 2>&1 || {
    echo "camera_driver failed on $name; see $out/logs/$name.driver.log" >&2; exit 1; }
  rm -rf "$out/runs/$name"
  start=$(date +%s.%N)
  run_service "$log" "$out/runs/$name" ${service_args[@]+"${service_args[@]}"}
  printf "  %-15s %4d images, service %.1f s\n" "$name" "$(ls "$root/JPEGImages/$name" | wc -l)" \
    "$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {print b - a}')"
done
seq_list=$(IFS=,; echo "${names[*]}")
res=$(last_json "$MBSLAM_BIN/mbslam-eval-realdata" davis --root "$root" --runs "$out/runs" \
      --sequences "$seq_list" --per-frame-dir "$out/per_frame")
python3 - "$res" "$rate" "$calib" "${service_args[*]+${service_args[*]}}" <<'PY'
import json, sys
res = json.loads(sys.argv[1])
if not res:
    print("{}"); sys.exit(0)
out = {"mean_precision": res.get("mean_precision"), "mean_recall": res.get("mean_recall"),
       "mean_iou": res.get("mean_iou")}
out.update({k: v for k, v in res.items() if k not in out})
out["rate_hz"] = float(sys.argv[2])
out["calibration"] = sys.argv[3].split("/")[-1]
out["intrinsics_note"] = "approximate: focal = image width, principal point at the image centre, no distortion"
out["service_args"] = sys.argv[4]
print(json.dumps(out))
PY
