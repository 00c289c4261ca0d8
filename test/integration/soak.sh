#!/usr/bin/env bash
# Soak: perception_service (realtime) fed live over udpm:// by camera_driver looping a
# simulated sequence for MINUTES, its resident memory sampled every few seconds.
# Runs ONLY inside a private network namespace (test/netns/run_in_netns.sh).
#
#   soak.sh BIN_DIR TESTS_DIR MINUTES OUT_DIR [--scenario NAME] [--max-slope MB_PER_MIN]
#           [--set section.key=value ...]   (perception_service options)
#
# Memory may grow only with the map: after a warm-up, the per-minute minimum of RSS minus
# the map's own memory (per-element costs of the SLAM map, the published OcTree) and minus
# the trajectories kept for the output files must not trend up by more than --max-slope
# (default 0.5 MB/min). Whether the map itself levelled
# off is reported (map_bounded: no growth over the second half, one-sided). The soak test
# runs with a small map (slam.max_keyframes=40, no occupancy map) where any trend is a
# leak; note that a map this small always gets a global BA (ba.global_max_keyframes=40),
# which also removes under-observed points: --default-config is the run that exercises
# culling with local BA only (map points left by culled keyframes once grew without
# bound there). LeakSanitizer (--asan) covers every module. With an AddressSanitizer
# build the LeakSanitizer report at exit must be clean and the RSS slope is not judged
# (quarantine, shadow memory).
# Prints a summary, then one JSON object as the LAST line. Exit 1 on a failed check.
set -euo pipefail
# The whole script is one function, read in full before it runs (editing the file during a
# 20-minute run cannot change what runs).
main() {
bin="${1:?BIN_DIR}"
tests="${2:?TESTS_DIR}"
minutes="${3:?MINUTES}"
out="${4:?OUT_DIR}"
shift 4
scenario=crossing
max_slope=0.5
service_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --scenario) scenario="$2"; shift 2 ;;
    --set) service_args+=(--set "$2"); shift 2 ;;
    --max-slope) max_slope="$2"; shift 2 ;;
    *) echo "soak.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
if ip -o link 2>/dev/null | grep -v ': lo:' | grep -q .; then
  echo "soak.sh: interfaces besides lo are visible: run me through test/netns/run_in_netns.sh" >&2
  exit 2
fi
mkdir -p "$out"
url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304"
seq="$out/sequence"
if [[ ! -f "$seq/timestamps.txt" ]]; then
  ASAN_OPTIONS=detect_leaks=0 "$bin/mbslam-sim" --quiet --scenario "$scenario" --size 320x240 --fps 30 --frames 300 --depth png \
    --out "$seq" >"$out/sim.log" 2>&1
fi

# Sanitizer builds: the service's leak report goes to a file of its own.
rm -f "$out"/lsan_service.*
ASAN_OPTIONS="detect_leaks=1:log_path=$out/lsan_service" \
  "$bin/perception_service" --lcm-url "$url" --mode realtime "${service_args[@]}" >"$out/service.log" 2>&1 &
service=$!
sleep 2
ASAN_OPTIONS=detect_leaks=0 "$bin/camera_driver" --source sequence --input "$seq" --lcm-url "$url" --loops 0 --speed 1 \
  --no-progress --quiet >"$out/driver.log" 2>&1 &
driver=$!
cleanup() {
  kill "$driver" 2>/dev/null || true
  kill "$service" 2>/dev/null || true
}
trap cleanup EXIT

"$tests/soak_monitor" --url "$url" --pid "$service" --seconds "$((minutes * 60))" --interval 5 >"$out/rss.csv" 2>"$out/monitor.log"
kill -TERM "$driver" 2>/dev/null || true
wait "$driver" 2>/dev/null || true
service_alive=1
kill -0 "$service" 2>/dev/null || service_alive=0
kill -TERM "$service" 2>/dev/null || true
service_exit=0
wait "$service" || service_exit=$?
trap - EXIT

asan=0
if ldd "$bin/perception_service" 2>/dev/null | grep -q libasan || \
   nm "$bin/perception_service" 2>/dev/null | grep -q __asan_init; then
  asan=1
fi
leaks="null"
if [[ "$asan" == 1 ]]; then
  leaks=0
  if ls "$out"/lsan_service.* >/dev/null 2>&1; then
    leaks=$(cat "$out"/lsan_service.* | grep -c "^Direct leak\|^Indirect leak" || true)
    cat "$out"/lsan_service.* | head -80 >&2
  fi
fi

python3 - "$out/rss.csv" "$minutes" "$max_slope" "$service_alive" "$service_exit" "$asan" "$leaks" "$scenario" <<'PY'
import csv, json, sys
path, minutes, max_slope = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
alive, exit_code, asan, leaks, scenario = int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6]), sys.argv[7], sys.argv[8]
leaks = None if leaks == "null" else int(leaks)
rows = [r for r in csv.DictReader(open(path))]
MB = 1024.0 * 1024.0
# The map's own memory, per element as measured (mallinfo2) on the real Map class
# (services/perception/slam/map.h): a point with its 11x11 patch ~610 B plus ~42 B per
# observation, a keyframe with ~300 static tracks ~46 KB; rounded up. The OcTree: the
# memoryUsage() of the published tree read back (a lower bound of the service's copy).
POINT_B, OBSERVATION_B, KEYFRAME_B = 650.0, 48.0, 48.0 * 1024
def map_mb(r):
    return (float(r["map_points"]) * POINT_B + float(r["map_observations"]) * OBSERVATION_B +
            float(r["map_keyframes"]) * KEYFRAME_B + float(r["occupancy_mem_bytes"])) / MB
# What the service keeps for its trajectory files (ResultRecorder: 64 B a pose, vectors
# growing by doubling: 96 B on average), bounded by ResultRecorder::kDefaultMaxPoses.
POSE_B = 96.0
def trajectory_mb(r):
    return float(r["trajectory_poses"]) * POSE_B / MB
t = [float(r["t_s"]) / 60.0 for r in rows]
rss = [float(r["rss_mb"]) for r in rows]

def fit(xs, ys):
    n = len(xs)
    if n < 3:
        return None
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else None

# After a warm-up (10 % of the run, at least 1 min): the retained memory is the minimum
# of each minute (transient peaks -- bundle adjustment, message buffers -- excluded).
warm = max(1.0, 0.1 * minutes)
bins = {}
for i, r in enumerate(rows):
    if t[i] < warm:
        continue
    b = int(t[i])
    if b not in bins or rss[i] < rss[bins[b]]:
        bins[b] = i
mins = [bins[b] for b in sorted(bins)]
slope_raw = fit([t[i] for i in range(len(rows)) if t[i] >= warm], [rss[i] for i in range(len(rows)) if t[i] >= warm])
slope_min = fit([t[i] for i in mins], [rss[i] for i in mins])
slope_map = fit([t[i] for i in mins], [map_mb(rows[i]) for i in mins])
slope_traj = fit([t[i] for i in mins], [trajectory_mb(rows[i]) for i in mins])
slope_beyond = fit([t[i] for i in mins], [rss[i] - map_mb(rows[i]) - trajectory_mb(rows[i]) for i in mins])
half = [i for i in range(len(rows)) if t[i] >= t[-1] / 2] if rows else []
def growth(col):  # per minute over the second half
    return fit([t[i] for i in half], [float(rows[i][col]) for i in half])
frames = int(rows[-1]["frames_processed"]) if rows else 0
received = int(rows[-1]["frames_received"]) if rows else 0
dropped = int(rows[-1]["frames_dropped"]) if rows else 0
duration = t[-1] if t else 0.0
r2 = lambda v: None if v is None else round(v, 4)
# Under AddressSanitizer the RSS is no measure of retained memory: freed blocks stay in
# its quarantine (256 MB by default) and every allocation has shadow and redzones, so
# a 5-minute run grows by hundreds of MB without a leak. There the verdict is
# LeakSanitizer's; the slopes are printed but not judged.
slope_ok = asan == 1 or (slope_beyond is not None and slope_beyond <= max_slope)
ok = (alive == 1 and exit_code == 0 and duration >= 0.95 * minutes and frames > 0 and
      slope_ok and (leaks in (None, 0)))
out = {
    "scenario": scenario, "duration_min": round(duration, 2), "samples": len(rows),
    "rss_start_mb": rss[0] if rss else None, "rss_end_mb": rss[-1] if rss else None,
    "rss_max_mb": max(rss) if rss else None,
    "rss_slope_mb_per_min": r2(slope_raw),
    "rss_retained_slope_mb_per_min": r2(slope_min),
    "map_mem_slope_mb_per_min": r2(slope_map),
    "trajectory_mem_slope_mb_per_min": r2(slope_traj),
    "rss_slope_beyond_map_mb_per_min": r2(slope_beyond),
    "max_slope_mb_per_min": max_slope,
    "map_mem_end_mb": round(map_mb(rows[-1]), 2) if rows else None,
    "map_points_end": int(rows[-1]["map_points"]) if rows else 0,
    "map_points_max": max((int(r["map_points"]) for r in rows), default=0),
    "map_keyframes_max": max((int(r["map_keyframes"]) for r in rows), default=0),
    "occupancy_mem_mb_end": round(float(rows[-1]["occupancy_mem_bytes"]) / MB, 2) if rows else None,
    "map_points_growth_per_min_2nd_half": r2(growth("map_points")),
    # Bounded = not growing over the second half (a map shrinking or oscillating after
    # culling is bounded too: the test is one-sided).
    "map_bounded": bool(rows) and (growth("map_points") or 0.0) <= 0.01 * max(1, max(int(r["map_points"]) for r in rows)) and
                   (growth("occupancy_mem_bytes") or 0.0) <= 0.05 * MB,
    "occupancy_mem_growth_mb_per_min_2nd_half": r2(None if growth("occupancy_mem_bytes") is None else growth("occupancy_mem_bytes") / MB),
    "frames": frames, "frames_received": received, "frames_dropped": dropped,
    "service_alive_at_end": bool(alive), "service_exit": exit_code,
    "asan": bool(asan), "lsan_leaks": leaks, "rss_slope_judged": asan != 1, "passed": ok,
}
print(f"soak ({scenario}, {duration:.1f} min{', ASan/LSan' if asan else ''}): RSS {out['rss_start_mb']} -> "
      f"{out['rss_end_mb']} MB (max {out['rss_max_mb']}); slope {out['rss_slope_mb_per_min']} MB/min, retained "
      f"{out['rss_retained_slope_mb_per_min']}, of which the map {out['map_mem_slope_mb_per_min']} and the "
      f"trajectories {out['trajectory_mem_slope_mb_per_min']}: "
      f"beyond the map {out['rss_slope_beyond_map_mb_per_min']} MB/min "
      f"({'limit ' + str(max_slope) if asan != 1 else 'not judged under ASan: quarantine'})")
print(f"  map at the end {out['map_mem_end_mb']} MB: {out['map_points_end']} points (max {out['map_points_max']}), "
      f"{out['map_keyframes_max']} keyframes max, OcTree {out['occupancy_mem_mb_end']} MB; second half: points "
      f"{out['map_points_growth_per_min_2nd_half']}/min, OcTree {out['occupancy_mem_growth_mb_per_min_2nd_half']} MB/min"
      f" ({'bounded' if out['map_bounded'] else 'NOT bounded'})")
print(f"  frames processed {frames} of {received} received ({dropped} dropped as stale)")
if asan:
    print(f"  LeakSanitizer: {leaks} leak reports")
print(f"  service exit {exit_code}, {'PASSED' if ok else 'FAILED'}")
print(json.dumps(out))
sys.exit(0 if ok else 1)
PY
}
main "$@"
exit $?
