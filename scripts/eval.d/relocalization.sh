#!/usr/bin/env bash
# Relocalisation in a saved map (issue SLAM: "relocalise against the existing map when the
# camera returns"; map save / load): TartanAir indoor, a first run over all 189 images
# saves its map (slam.map_save_path); second runs starting further along the same path
# load it (slam.map_load_path) and must place their images in it. A map of the first 80
# images only, loaded by runs that start where it has nothing, must place nothing.
#
#   scripts/eval.sh relocalization [--starts "40 100 150"] [--unmapped-starts "110 150"]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to every run)
#
# Per start: the first image placed live (the relocalisation), the share of the images
# with a pose in the trajectory file, relocalisations (pose_relocalized), and the ATE of
# the second run scored in the first run's frame: the Sim(3) that aligns the first run
# to the truth is applied to the second run as it is (mbslam-eval ate --align-est), so a
# second run that made its own map instead of using the loaded one is far off; beside it
# the first run's own ATE (the map's accuracy) and the second run's under its own Sim(3).
# JSON (last line): {"map": {"images", "ate_m", "ate_rel_path", "described_points",
#   "points"}, "starts": {"K": {"images", "first_posed_image", "tracked_fraction",
#   "relocalizations", "tracking_lost", "ate_in_map_m", "ate_own_m", "path_length_m"}},
#   "unmapped": {"K": {"images", "posed_images", "relocalizations"}},
#   "tracked_fraction_mean", "ate_in_map_m_mean", "false_relocalizations" (posed images of
#   the unmapped runs: each is a wrong placement),
#   "enter": {...}, "blackout": {...}}
#
# Kept lost maps (slam.lost_maps_kept), two more cases:
# * enter: a map of images ENTER.. only (--enter 100) is loaded by a run over all the
#   images that does not wait for it (slam.reloc_loaded_max_frames 1: a new map is made
#   at once and the loaded one is kept); when the camera reaches the mapped part the
#   loaded map replaces the new one. JSON "enter": {"rejoined_image", "maps_rejoined",
#   "tracked_fraction", "ate_in_map_m" (the images from the rejoin on, in the loaded
#   map's frame as above)}. (Under one Sim(3) the whole run would not score: it holds
#   two maps, each with its own scale.)
# * blackout: a run over all the images with BLACKOUT_FRAMES (6) black images from each
#   of --blackout "60 80 120" (a covered lens: the map is lost and given up), with the lost
#   map kept (default) and with slam.lost_maps_kept 0. JSON "blackout": {"K": {"kept":
#   {...}, "not_kept": {...}}} each with "maps_rejoined", "first_posed_after", "tracked_fraction",
#   "ate_own_m" (own Sim(3) over all posed images), "ate_after_m" (the 30 images after
#   the blackout in the Sim(3) of the images before it: a new map's frame is carried over
#   the gap by the last velocity, a rejoined map's is the old one).
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
starts="40 100 150"
unmapped_starts="110 150"
enter=100
blackouts="60 80 120"
blackout_frames="${BLACKOUT_FRAMES:-6}"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --starts) starts="$2"; shift 2 ;;
    --unmapped-starts) unmapped_starts="$2"; shift 2 ;;
    --enter) enter="$2"; shift 2 ;;
    --blackout) blackouts="$2"; shift 2 ;;
    *) echo "relocalization: unknown argument $1" >&2; echo '{}'; exit 2 ;;
  esac
done
for k in $starts $unmapped_starts $enter $blackouts $blackout_frames; do
  if ! [[ "$k" =~ ^[0-9]+$ ]]; then echo "relocalization: starts are image indices, not '$k'" >&2; echo '{}'; exit 2; fi
done
data="$MBSLAM_DATA/tartanair_indoor_subset"
if [[ ! -d "$data/images" ]]; then
  echo "relocalization: $data not found (set MBSLAM_DATA)" >&2; echo '{"skipped": true}'; exit 0
fi
out="$MBSLAM_EVAL_OUT"
mkdir -p "$out"
read -r -a service_args <<< "${SERVICE_ARGS:-}"

# log_of NAME START [END] -> the camera log of those images (10 Hz, as realdata-slam)
log_of() {
  local name="$1" k="$2" end="${3:-}" dir="$out/$1"
  tartanair_from "$k" "$data" "$dir/data" "$end"
  "$MBSLAM_BIN/camera_driver" --source tartanair --input "$dir/data" --rate 10 \
    --calibration "$MBSLAM_ROOT/config/camera/tartanair.yaml" --log "$dir/camera.lcmlog" --quiet --no-progress \
    --log-level warning >&2
  echo "$dir/camera.lcmlog"
}

# The maps: all images, and the first 80.
map_log=$(log_of map 0)
run_service "$map_log" "$out/map/run" ${service_args[@]+"${service_args[@]}"} --set slam.map_save_path="$out/map/all.map"
part_log=$(log_of map80 0 80)
run_service "$part_log" "$out/map80/run" ${service_args[@]+"${service_args[@]}"} --set slam.map_save_path="$out/map80/first80.map"
map_ate=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$out/map/run/result/camera_trajectory.tum" --gt-log "$map_log")

runs=()
for k in $starts; do
  log=$(log_of "from$k" "$k")
  run_service "$log" "$out/from$k/run" ${service_args[@]+"${service_args[@]}"} --set slam.map_load_path="$out/map/all.map"
  in_map=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$out/from$k/run/result/camera_trajectory.tum" --gt-log "$log" \
           --align-est "$out/map/run/result/camera_trajectory.tum" --align-gt-log "$map_log" \
           --plot "$out/from$k/in_map.png")
  own=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$out/from$k/run/result/camera_trajectory.tum" --gt-log "$log")
  runs+=("$k" "$out/from$k" "$in_map" "$own")
done
unmapped=()
for k in $unmapped_starts; do
  log=$(log_of "unmapped$k" "$k")
  run_service "$log" "$out/unmapped$k/run" ${service_args[@]+"${service_args[@]}"} \
    --set slam.map_load_path="$out/map80/first80.map"
  unmapped+=("$k" "$out/unmapped$k")
done

# Kept maps: entering a loaded map's part of the path from outside it.
enter_log=$(log_of "map_from$enter" "$enter")
run_service "$enter_log" "$out/map_from$enter/run" ${service_args[@]+"${service_args[@]}"} \
  --set slam.map_save_path="$out/map_from$enter/from$enter.map"
log=$(log_of enter 0)
run_service "$log" "$out/enter/run" ${service_args[@]+"${service_args[@]}"} \
  --set slam.map_load_path="$out/map_from$enter/from$enter.map" --set slam.reloc_loaded_max_frames=1
# after_rejoin RUN_DIR IMAGE OUT_TUM: the trajectory file's images from IMAGE on (10 Hz stamps from 0)
after_image() {
  awk -v t="$(awk -v i="$2" 'BEGIN {printf "%.6f", i / 10.0 - 0.05}')" '/^#/ || $1 >= t' \
    "$1/run/result/camera_trajectory.tum" > "$3"
}
# rejoined_image RUN_DIR -> the first image a kept map was taken up again at, or -1
rejoined_image() {
  local f
  f=$(grep -o 'frame [0-9]*: kept map [0-9]* placed the image' "$1/run/service.log" | head -1 | awk '{print $2}' | tr -d :)
  echo "${f:--1}"
}
enter_at=$(rejoined_image "$out/enter")
enter_in_map="{}"
if [[ "$enter_at" -ge 0 ]]; then
  after_image "$out/enter" "$enter_at" "$out/enter/after_rejoin.tum"
  enter_in_map=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$out/enter/after_rejoin.tum" --gt-log "$log" \
                 --align-est "$out/map_from$enter/run/result/camera_trajectory.tum" --align-gt-log "$enter_log")
fi
enter_own=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$out/enter/run/result/camera_trajectory.tum" --gt-log "$log")

# Kept maps: a covered lens. BLACKOUT_FRAMES black images (a PNG under the .jpg name:
# the reader goes by content) replace those from K on.
black="$out/black.jpg"
python3 - "$black" <<'PY'
import struct, sys, zlib
w, h = 640, 480
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
raw = b"".join(b"\0" + bytes(3 * w) for _ in range(h))
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                              + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
PY
blackout_runs=()
for k in $blackouts; do
  dir="$out/blackout$k"
  tartanair_from 0 "$data" "$dir/data"
  for ((i = k; i < k + blackout_frames; i++)); do
    ln -sf "$black" "$dir/data/images/$(printf %06d_left.jpg "$i")"
  done
  "$MBSLAM_BIN/camera_driver" --source tartanair --input "$dir/data" --rate 10 \
    --calibration "$MBSLAM_ROOT/config/camera/tartanair.yaml" --log "$dir/camera.lcmlog" --quiet --no-progress \
    --log-level warning >&2
  for kept in kept not_kept; do
    extra=()
    if [[ "$kept" == not_kept ]]; then extra=(--set slam.lost_maps_kept=0); fi
    run_service "$dir/camera.lcmlog" "$dir/$kept/run" ${service_args[@]+"${service_args[@]}"} ${extra[@]+"${extra[@]}"}
    own=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$dir/$kept/run/result/camera_trajectory.tum" --gt-log "$dir/camera.lcmlog")
    # The images before the blackout fix the Sim(3); those after it are scored in it.
    awk -v t="$(awk -v i="$k" 'BEGIN {printf "%.6f", i / 10.0 - 0.05}')" '/^#/ || $1 < t' \
      "$dir/$kept/run/result/camera_trajectory.tum" > "$dir/$kept/before.tum"
    # The 30 images after it (3 s): does the trajectory go on in the same frame?
    awk -v a="$(awk -v i="$((k + blackout_frames))" 'BEGIN {printf "%.6f", i / 10.0 - 0.05}')" \
        -v b="$(awk -v i="$((k + blackout_frames + 30))" 'BEGIN {printf "%.6f", i / 10.0 - 0.05}')" \
        '/^#/ || ($1 >= a && $1 < b)' "$dir/$kept/run/result/camera_trajectory.tum" > "$dir/$kept/after.tum"
    after=$(last_json "$MBSLAM_BIN/mbslam-eval" ate --est "$dir/$kept/after.tum" --gt-log "$dir/camera.lcmlog" \
            --align-est "$dir/$kept/before.tum" --align-gt-log "$dir/camera.lcmlog")
    blackout_runs+=("$k" "$kept" "$dir/$kept" "$own" "$after")
  done
done

python3 - "$out" "$map_ate" "$enter_at" "$enter_in_map" "$enter_own" "$blackout_frames" "${#blackout_runs[@]}" \
  "${blackout_runs[@]}" "${#runs[@]}" "${runs[@]}" "${unmapped[@]}" <<'PY'
import json, math, os, sys
out, map_ate = sys.argv[1], json.loads(sys.argv[2] or "{}")
enter_at, enter_in_map, enter_own = int(sys.argv[3]), json.loads(sys.argv[4] or "{}"), json.loads(sys.argv[5] or "{}")
blackout_frames = int(sys.argv[6])
nb = int(sys.argv[7]); blackout_runs = sys.argv[8:8 + nb]
rest = sys.argv[8 + nb:]
n = int(rest[0]); runs = rest[1:1 + n]; unmapped = rest[1 + n:]

def images(run_dir):
    return len([f for f in os.listdir(os.path.join(run_dir, "data", "images")) if f.endswith("_left.jpg")])

def summary(run_dir):
    path = os.path.join(run_dir, "run", "result", "summary.json")
    return json.load(open(path)) if os.path.exists(path) else {}

def first_live_image(run_dir):
    path = os.path.join(run_dir, "run", "result", "camera_trajectory_live.tum")
    if not os.path.exists(path): return None
    for line in open(path):
        if line.startswith("#") or not line.strip(): continue
        return int(round(float(line.split()[0]) * 10.0))  # 10 Hz stamps from 0
    return None

def described(map_path):
    total = with_descriptor = 0
    if not os.path.exists(map_path): return 0, 0
    reading = False
    for line in open(map_path):
        w = line.split()
        if w and w[0] == "points": reading = True; continue
        if reading and len(w) > 6:
            total += 1; with_descriptor += w[-3] != "-" if w[-1] != "0" else w[-2] != "-"
    return with_descriptor, total

def path_length(run_dir):
    pts = [list(map(float, l.split()[:3])) for l in open(os.path.join(run_dir, "data", "pose_left.txt")) if l.strip()]
    return sum(math.dist(a, b) for a, b in zip(pts, pts[1:]))

res = {}
d, t = described(os.path.join(out, "map", "all.map"))
res["map"] = {"images": images(os.path.join(out, "map")), "ate_m": map_ate.get("ate_rmse_m"),
              "ate_rel_path": (map_ate["ate_rmse_m"] / path_length(os.path.join(out, "map"))) if "ate_rmse_m" in map_ate else None,
              "described_points": d, "points": t}
res["starts"] = {}
for i in range(0, len(runs), 4):
    k, run_dir, in_map, own = runs[i], runs[i + 1], json.loads(runs[i + 2] or "{}"), json.loads(runs[i + 3] or "{}")
    s = summary(run_dir); c = s.get("counters", {})
    res["starts"][k] = {"images": images(run_dir), "first_posed_image": first_live_image(run_dir),
                        "tracked_fraction": in_map.get("fraction_tracked"),
                        "relocalizations": c.get("pose_relocalized", 0), "tracking_lost": c.get("tracking_lost", 0),
                        "ate_in_map_m": in_map.get("ate_rmse_m"), "ate_own_m": own.get("ate_rmse_m"),
                        "path_length_m": path_length(run_dir)}
res["unmapped"] = {}
false_placements = 0
for i in range(0, len(unmapped), 2):
    k, run_dir = unmapped[i], unmapped[i + 1]
    s = summary(run_dir); c = s.get("counters", {})
    posed = s.get("frames_tracked", 0)
    false_placements += posed
    res["unmapped"][k] = {"images": images(run_dir), "posed_images": posed, "relocalizations": c.get("pose_relocalized", 0)}
vals = [v for v in res["starts"].values()]
def mean(key):
    xs = [v[key] for v in vals if v.get(key) is not None]
    return sum(xs) / len(xs) if xs else None
res["tracked_fraction_mean"] = mean("tracked_fraction")
res["ate_in_map_m_mean"] = mean("ate_in_map_m")
res["false_relocalizations"] = false_placements

def live_images(run_dir):
    path = os.path.join(run_dir, "run", "result", "camera_trajectory_live.tum")
    if not os.path.exists(path): return []
    return [int(round(float(l.split()[0]) * 10.0)) for l in open(path) if l.strip() and not l.startswith("#")]

s = summary(os.path.join(out, "enter"))
res["enter"] = {"images": images(os.path.join(out, "enter")), "rejoined_image": enter_at,
                "maps_rejoined": s.get("counters", {}).get("map_rejoined", 0),
                "tracked_fraction": enter_own.get("fraction_tracked"),
                "ate_in_map_m": enter_in_map.get("ate_rmse_m")}
res["blackout"] = {}
for i in range(0, len(blackout_runs), 5):
    k, kept, run_dir = blackout_runs[i], blackout_runs[i + 1], blackout_runs[i + 2]
    own, after = json.loads(blackout_runs[i + 3] or "{}"), json.loads(blackout_runs[i + 4] or "{}")
    s = summary(run_dir)
    first = [f for f in live_images(run_dir) if f >= int(k) + blackout_frames]
    res["blackout"].setdefault(k, {})[kept] = {
        "maps_rejoined": s.get("counters", {}).get("map_rejoined", 0),
        "first_posed_after": (first[0] - int(k) - blackout_frames) if first else None,
        "tracked_fraction": own.get("fraction_tracked"), "ate_own_m": own.get("ate_rmse_m"),
        "ate_after_m": after.get("ate_rmse_m")}
print(json.dumps(res))
PY
