#!/usr/bin/env python3
"""Verdict of a soak run (test/integration/soak.sh) from the monitor's CSV.

  soak_judge.py RSS_CSV MINUTES MAX_SLOPE SERVICE_ALIVE SERVICE_EXIT ASAN LEAKS SCENARIO [OCCUPANCY_CAP_MB]

Re-scores a finished run without running it again (e.g. out/eval/soak*/run*/rss.csv
with MINUTES 20 MAX_SLOPE 0.5 1 0 0 null crossing). Prints a summary and, last, the
JSON; exits 0 when the run passed.
"""
import csv, json, sys
path, minutes, max_slope = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
alive, exit_code, asan, leaks, scenario = int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6]), sys.argv[7], sys.argv[8]
# occupancy.max_memory_mb of the run (the service's default 64): the OcTree's bound.
occupancy_cap_mb = float(sys.argv[9]) if len(sys.argv) > 9 else 64.0
leaks = None if leaks == "null" else int(leaks)
rows = [r for r in csv.DictReader(open(path))]
MB = 1024.0 * 1024.0
# The map's own memory, per element as measured (mallinfo2) on the real Map class
# (services/perception/slam/map.h): a point with its 11x11 patch ~610 B plus ~42 B per
# observation, a keyframe with ~300 static tracks ~46 KB; rounded up. The OcTree: the
# service's estimate of its own tree (occupancy_t.memory_bytes).
POINT_B, OBSERVATION_B, KEYFRAME_B = 650.0, 48.0, 48.0 * 1024
def map_mb(r):
    return (float(r["map_points"]) * POINT_B + float(r["map_observations"]) * OBSERVATION_B +
            float(r["map_keyframes"]) * KEYFRAME_B + float(r["occupancy_mem_bytes"])) / MB
# What the service keeps for its output files (ResultRecorder: trajectories and object
# reconstructions, bounded by ResultRecorder::kDefaultMaxPoses): as it reports it
# (status_t.results_kept_bytes), or, in older CSVs, estimated from the poses the monitor
# saw published (64 B a pose, vectors growing by doubling: 96 B on average; this misses
# the reconstructions' poses and points).
POSE_B = 96.0
def trajectory_mb(r):
    kept = float(r.get("results_kept_mb") or -1.0)
    return kept if kept >= 0.0 else float(r["trajectory_poses"]) * POSE_B / MB
t = [float(r["t_s"]) / 60.0 for r in rows]
rss = [float(r["rss_mb"]) for r in rows]

def fit(xs, ys):
    n = len(xs)
    if n < 3:
        return None
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else None

# The C heap from the service's PERCEPTION_STATUS (absent in older CSVs, -1 when the
# service cannot tell: sanitizers, another libc): allocated and not freed, and held.
# Samples before the first status (or without figures) are None.
def column(name):
    if not rows or name not in rows[0]:
        return None
    v = [float(r[name]) if float(r[name]) >= 0.0 else None for r in rows]
    return v if any(x is not None for x in v) else None
heap = column("heap_in_use_mb")
heap_held = column("heap_held_mb")

# After a warm-up (10 % of the run, at least 1 min): the retained memory is the minimum
# of each minute (transient peaks -- bundle adjustment, message buffers -- excluded).
# Whole minutes only: a last, partial minute (the run ends at 20.0 min, one sample in
# minute 20) has no minimum of a minute, and its one sample would enter the trend with
# the weight of a minute.
warm = max(1.0, 0.1 * minutes)
dt = sorted(t[i + 1] - t[i] for i in range(len(t) - 1))[(len(t) - 1) // 2] if len(t) > 1 else 0.0
def minute_minima(values):
    bins = {}
    for i in range(len(rows)):
        b = int(t[i])
        if t[i] < warm or b + 1 > t[-1] + 0.5 * dt or values[i] is None:
            continue
        if b not in bins or values[i] < values[bins[b]]:
            bins[b] = i
    return [bins[b] for b in sorted(bins)]
mins = minute_minima(rss)
slope_raw = fit([t[i] for i in range(len(rows)) if t[i] >= warm], [rss[i] for i in range(len(rows)) if t[i] >= warm])
slope_min = fit([t[i] for i in mins], [rss[i] for i in mins])
slope_map = fit([t[i] for i in mins], [map_mb(rows[i]) for i in mins])
slope_traj = fit([t[i] for i in mins], [trajectory_mb(rows[i]) for i in mins])
# The allocator keeps what the map frees (culled points, a cropped OcTree) for its later
# growth instead of returning it to the system, so after the map shrinks the RSS stays at
# the map's largest size: what the map accounts for is its high-water mark so far.
map_high = []
for r in rows:
    map_high.append(max(map_high[-1] if map_high else 0.0, map_mb(r)))
# Judged in the steady state, the second half of the run: with the default configuration
# the map takes minutes to reach its bounds (200 keyframes after ~2 min, the OcTree's
# memory bound after ~12), and while it grows the RSS runs ahead of the per-element
# estimates above (allocator fragmentation). The whole run after the warm-up is reported.
steady = [i for i in mins if t[i] >= t[-1] / 2] if rows else []
slope_beyond = fit([t[i] for i in steady], [rss[i] - map_high[i] - trajectory_mb(rows[i]) for i in steady])
# The leak test proper: the heap in use beyond what the map and the trajectories hold now
# (freed memory leaves the heap in use, so the current map counts, not its high-water
# mark), per-minute minima in the second half. The RSS above also moves with how the
# allocator keeps and reuses what was freed (fragmentation, per-thread arenas).
heap_slope_beyond = heap_slope_beyond_full = heap_held_slope = None
if heap is not None:
    hmins = minute_minima(heap)
    hsteady = [i for i in hmins if t[i] >= t[-1] / 2]
    beyond = lambda i: heap[i] - map_mb(rows[i]) - trajectory_mb(rows[i])
    heap_slope_beyond = fit([t[i] for i in hsteady], [beyond(i) for i in hsteady])
    heap_slope_beyond_full = fit([t[i] for i in hmins], [beyond(i) for i in hmins])
if heap_held is not None:
    gmins = [i for i in minute_minima(heap_held) if t[i] >= t[-1] / 2]
    heap_held_slope = fit([t[i] for i in gmins], [heap_held[i] for i in gmins])
slope_beyond_full = fit([t[i] for i in mins], [rss[i] - map_high[i] - trajectory_mb(rows[i]) for i in mins])
# Against the current map size instead (reported, not judged: steps up at every crop).
slope_beyond_current = fit([t[i] for i in mins], [rss[i] - map_mb(rows[i]) - trajectory_mb(rows[i]) for i in mins])
half = [i for i in range(len(rows)) if t[i] >= t[-1] / 2] if rows else []
first_half = [i for i in range(len(rows)) if warm <= t[i] < t[-1] / 2] if rows else []
def half_max(col, idx):
    return max((float(rows[i][col]) for i in idx), default=0.0)
# Bounded: map points do not exceed the first half's largest count by more than 10 % in
# the second half (a map oscillating under keyframe culling is bounded; one that keeps
# growing is not), and the OcTree stays within its memory bound (plus 10 % for the
# keyframe that crosses it before the crop).
def bounded(col):
    return half_max(col, half) <= 1.1 * max(1.0, half_max(col, first_half))
def occupancy_bounded():
    return max((float(r["occupancy_mem_bytes"]) for r in rows), default=0.0) <= 1.1 * occupancy_cap_mb * MB
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
# Both must hold: the RSS (what the machine gives up) and, where the service reports it,
# the heap in use (a leak shows there even when the allocator's reuse hides it in the RSS,
# and the allocator's churn does not show there).
heap_ok = heap_slope_beyond is None or heap_slope_beyond <= max_slope
slope_ok = asan == 1 or (slope_beyond is not None and slope_beyond <= max_slope and heap_ok)
map_bounded = bool(rows) and bounded("map_points") and occupancy_bounded()
ok = (alive == 1 and exit_code == 0 and duration >= 0.95 * minutes and frames > 0 and
      slope_ok and map_bounded and (leaks in (None, 0)))
out = {
    "scenario": scenario, "duration_min": round(duration, 2), "samples": len(rows),
    "rss_start_mb": rss[0] if rss else None, "rss_end_mb": rss[-1] if rss else None,
    "rss_max_mb": max(rss) if rss else None,
    "rss_slope_mb_per_min": r2(slope_raw),
    "rss_retained_slope_mb_per_min": r2(slope_min),
    "map_mem_slope_mb_per_min": r2(slope_map),
    "trajectory_mem_slope_mb_per_min": r2(slope_traj),
    "rss_slope_beyond_map_mb_per_min": r2(slope_beyond),
    "rss_slope_beyond_map_full_run_mb_per_min": r2(slope_beyond_full),
    "rss_slope_beyond_current_map_mb_per_min": r2(slope_beyond_current),
    "heap_in_use_slope_beyond_map_mb_per_min": r2(heap_slope_beyond),
    "heap_in_use_slope_beyond_map_full_run_mb_per_min": r2(heap_slope_beyond_full),
    "heap_held_slope_mb_per_min": r2(heap_held_slope),
    "heap_in_use_end_mb": None if heap is None or heap[-1] is None else round(heap[-1], 2),
    "heap_held_end_mb": None if heap_held is None or heap_held[-1] is None else round(heap_held[-1], 2),
    "max_slope_mb_per_min": max_slope,
    "map_mem_end_mb": round(map_mb(rows[-1]), 2) if rows else None,
    "map_points_end": int(rows[-1]["map_points"]) if rows else 0,
    "map_points_max": max((int(r["map_points"]) for r in rows), default=0),
    "map_keyframes_max": max((int(r["map_keyframes"]) for r in rows), default=0),
    "occupancy_mem_mb_end": round(float(rows[-1]["occupancy_mem_bytes"]) / MB, 2) if rows else None,
    "map_points_growth_per_min_2nd_half": r2(growth("map_points")),
    "map_bounded": map_bounded,
    "occupancy_cap_mb": occupancy_cap_mb,
    "map_points_max_halves": [half_max("map_points", first_half), half_max("map_points", half)],
    "occupancy_mem_mb_max_halves": [round(half_max("occupancy_mem_bytes", first_half) / MB, 2),
                                     round(half_max("occupancy_mem_bytes", half) / MB, 2)],
    "occupancy_mem_growth_mb_per_min_2nd_half": r2(None if growth("occupancy_mem_bytes") is None else growth("occupancy_mem_bytes") / MB),
    "frames": frames, "frames_received": received, "frames_dropped": dropped,
    "service_alive_at_end": bool(alive), "service_exit": exit_code,
    "asan": bool(asan), "lsan_leaks": leaks, "rss_slope_judged": asan != 1,
    "heap_slope_judged": asan != 1 and heap_slope_beyond is not None, "passed": ok,
}
print(f"soak ({scenario}, {duration:.1f} min{', ASan/LSan' if asan else ''}): RSS {out['rss_start_mb']} -> "
      f"{out['rss_end_mb']} MB (max {out['rss_max_mb']}); slope {out['rss_slope_mb_per_min']} MB/min, retained "
      f"{out['rss_retained_slope_mb_per_min']}, of which the map {out['map_mem_slope_mb_per_min']} and the "
      f"trajectories {out['trajectory_mem_slope_mb_per_min']}: "
      f"beyond the map's high-water mark {out['rss_slope_beyond_map_mb_per_min']} MB/min in the second half "
      f"({out['rss_slope_beyond_map_full_run_mb_per_min']} over the whole run) "
      f"({'limit ' + str(max_slope) if asan != 1 else 'not judged under ASan: quarantine'})")
if heap is not None:
    print(f"  C heap: in use {out['heap_in_use_end_mb']} MB, held {out['heap_held_end_mb']} MB at the end; in use beyond "
          f"the map and the trajectories {out['heap_in_use_slope_beyond_map_mb_per_min']} MB/min in the second half "
          f"({out['heap_in_use_slope_beyond_map_full_run_mb_per_min']} over the whole run), held "
          f"{out['heap_held_slope_mb_per_min']} MB/min in the second half"
          f"{' (limit ' + str(max_slope) + ')' if asan != 1 else ''}")
print(f"  map at the end {out['map_mem_end_mb']} MB: {out['map_points_end']} points (max {out['map_points_max']}), "
      f"{out['map_keyframes_max']} keyframes max, OcTree {out['occupancy_mem_mb_end']} MB; second half: points "
      f"{out['map_points_growth_per_min_2nd_half']}/min, OcTree {out['occupancy_mem_growth_mb_per_min_2nd_half']} MB/min; "
      f"largest first / second half: points {out['map_points_max_halves']}, OcTree {out['occupancy_mem_mb_max_halves']} MB"
      f" ({'bounded' if out['map_bounded'] else 'NOT bounded'})")
print(f"  frames processed {frames} of {received} received ({dropped} dropped as stale)")
if asan:
    print(f"  LeakSanitizer: {leaks} leak reports")
print(f"  service exit {exit_code}, {'PASSED' if ok else 'FAILED'}")
print(json.dumps(out))
sys.exit(0 if ok else 1)
