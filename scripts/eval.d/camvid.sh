#!/usr/bin/env bash
# CamVid 0016E5 (101 frames, 15 Hz, car in traffic): share of moving-labelled features on static classes (target <= 5 %) and on cars / people
#
#   scripts/eval.sh camvid [--rate HZ] [--calibration YAML] [perception_service args...]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service too)
#
# images/ becomes an LCM log (camera_driver, folder source, 15 Hz nominal stamps), the
# service replays it lockstep and mbslam-eval-realdata scores PERCEPTION_TRACKS against
# labels/*.png. Intrinsics are a guess (config/camera/camvid_480x360.yaml: focal = width =
# 480 px, principal point at the centre). Outputs: $MBSLAM_EVAL_OUT/{camvid.lcmlog,run/}.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/_lib.sh"
root="${MBSLAM_DATA}/camvid_0016E5_15hz"
if [[ ! -d "$root/labels" ]]; then
  echo "camvid: $root not found (set MBSLAM_DATA)"; echo '{"skipped": true}'; exit 0
fi
rate=15
calib="$MBSLAM_ROOT/config/camera/camvid_480x360.yaml"
service_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --rate) rate="$2"; shift 2 ;;
    --calibration) calib="$2"; shift 2 ;;
    *) service_args+=("$1"); shift ;;
  esac
done
# SERVICE_ARGS="--set a.b=v ..." (as the other evaluations take it) adds to them.
read -r -a env_args <<< "${SERVICE_ARGS:-}"
service_args+=(${env_args[@]+"${env_args[@]}"})
out="$MBSLAM_EVAL_OUT"
log="$out/camvid.lcmlog"
"$MBSLAM_BIN/camera_driver" --source folder --input "$root/images" --rate "$rate" \
  --calibration "$calib" --encoding source --log "$log" >"$out/driver.log" 2>&1 || {
  echo "camera_driver failed; see $out/driver.log" >&2; exit 1; }
rm -rf "$out/run"
run_service "$log" "$out/run" ${service_args[@]+"${service_args[@]}"}
res=$(last_json "$MBSLAM_BIN/mbslam-eval-realdata" camvid --root "$root" --run "$out/run/out.lcmlog")
python3 - "$res" "$rate" "$calib" "${service_args[*]+${service_args[*]}}" <<'PY'
import json, sys
res = json.loads(sys.argv[1])
if not res:
    print("{}"); sys.exit(0)
out = {"moving_on_static_classes": res.get("moving_on_static_classes")}
out.update({k: v for k, v in res.items() if k not in out})
out["target_moving_on_static_classes"] = 0.05
out["rate_hz"] = float(sys.argv[2])
out["calibration"] = sys.argv[3].split("/")[-1]
out["intrinsics_note"] = "approximate: focal = image width, principal point at the image centre, no distortion"
out["service_args"] = sys.argv[4]
print(json.dumps(out))
PY
