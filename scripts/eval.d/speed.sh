#!/usr/bin/env bash
# Speed: perception_service live (realtime) at 640x480 fed at 30 Hz and 60 Hz through lcm-logplayer over udpm:// in a private netns; fps, latency and per-stage p50 / p99, peak RSS; sim-multi and a real sequence
#
#   scripts/eval.sh speed [--scenarios "sim-multi tartanair"] [--rates "30 60"] [--frames N]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the live service)
#
# Per scenario and input rate: lcm-logplayer plays the 640x480 log at the rate, the
# service runs live (stale frames dropped and counted), its summary.json gives the
# per-stage timing (p50 / p99 of wall time per frame) and the receive-to-publish latency;
# /usr/bin/time gives its peak RSS. fps = frames processed / seconds of input played.
# A further lockstep replay (every frame, file:// as fast as it goes) gives the
# throughput headroom: lockstep_fps.
# Run it on an otherwise idle machine: the figures are wall time on these cores.
# JSON (last line): {"sim-multi": {"fps", "latency_p50_ms", "latency_p99_ms", "peak_rss_mb",
#   "input_hz", "frames_sent", "frames_received", "frames_processed", "frames_dropped_stale",
#   "frames_lost_upstream", "stages": {...}, "at_60hz": {...}, "lockstep_fps"}, "tartanair": {...},
#   "load_average_before": ...}
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
scenarios="sim-multi tartanair"
rates="30 60"
frames=300
while [[ $# -gt 0 ]]; do
  case "$1" in
    --scenarios) scenarios="$2"; shift 2 ;;
    --rates) rates="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    *) echo "speed: unknown argument $1" >&2; echo '{}'; exit 2 ;;
  esac
done
out="$MBSLAM_EVAL_OUT"
mkdir -p "$out"
load_before=$(cut -d' ' -f1 /proc/loadavg)
echo "load average before: $load_before (figures are wall time; an idle machine is assumed)" >&2

# input_log SCENARIO -> prints "LOG NATIVE_HZ FRAMES" (640x480 images, 30 Hz)
input_log() {
  case "$1" in
    sim-multi)
      local seq
      seq=$(sim_sequence multi "$frames")
      echo "$seq/sequence.lcmlog 30 $frames" ;;
    tartanair)
      local data="$MBSLAM_DATA/tartanair_indoor_subset" log="$out/tartanair/input.lcmlog"
      if [[ ! -d "$data" ]]; then echo "none 0 0"; return; fi
      mkdir -p "$out/tartanair"
      if [[ ! -f "$log" ]]; then
        "$MBSLAM_BIN/camera_driver" --source tartanair --input "$data" --rate 30 \
          --calibration "$MBSLAM_ROOT/config/camera/tartanair.yaml" --log "$log" --quiet >&2
      fi
      echo "$log 30 $(grep -c . "$data/pose_left.txt")" ;;
    *) echo "none 0 0" ;;
  esac
}

results=()
for scenario in $scenarios; do
  read -r log native n <<<"$(input_log "$scenario")"
  if [[ "$log" == none ]]; then
    echo "speed: $scenario: no input (data missing or unknown scenario), skipped" >&2
    continue
  fi
  for rate in $rates; do
    run="$out/$scenario/${rate}hz"
    rm -rf "$run"
    mkdir -p "$run"
    speed=$(python3 -c "print($rate / $native)")
    "$MBSLAM_ROOT/test/netns/run_in_netns.sh" bash -c '
      set -u
      bin="$1"; log="$2"; run="$3"; speed="$4"; shift 4
      url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"
      /usr/bin/time -f "%M" -o "$run/time.txt" \
        "$bin/perception_service" --lcm-url "$url" --mode realtime --output-dir "$run/result" "$@" \
          2>"$run/service.log" &
      service=$!
      sleep 2
      lcm-logplayer --lcm-url="$url" --speed="$speed" "$log"
      sleep 2
      kill -INT $(pgrep -P "$service") 2>/dev/null || true
      wait "$service"; s=$?
      echo "service exit $s" >&2
      [[ $s -eq 0 ]]
    ' _ "$MBSLAM_BIN" "$log" "$run" "$speed" ${SERVICE_ARGS:-} || { echo "speed: $scenario at $rate Hz failed; see $run/service.log" >&2; }
  done
  # Lockstep headroom: every frame, as fast as it goes (inline bundle adjustment).
  lock="$out/$scenario/lockstep"
  rm -rf "$lock"
  t0=$(date +%s.%N)
  run_service "$log" "$lock" || true
  t1=$(date +%s.%N)
  echo "$t0 $t1" >"$lock/wall.txt"
  results+=("$scenario:$n")
done

python3 - "$out" "$load_before" "$rates" "${results[@]}" <<'PY'
import json, os, sys
out, load_before, rates = sys.argv[1], float(sys.argv[2]), [int(r) for r in sys.argv[3].split()]
report = {"load_average_before": load_before}
def run_figures(d, n, rate):
    try:
        s = json.load(open(os.path.join(d, "result", "summary.json")))
    except (OSError, ValueError):
        return None
    t = s.get("timings", {})
    c = s.get("counters", {})
    try:
        rss_kb = float(open(os.path.join(d, "time.txt")).read().split()[-1])
    except (OSError, ValueError, IndexError):
        rss_kb = None
    processed = s.get("frames", 0)
    seconds = n / float(rate)
    lost = c.get("image_frames_lost_upstream", 0)
    stale = c.get("image_dropped_stale", 0)
    return {
        "input_hz": rate, "frames_sent": n, "frames_received": processed + stale,
        "frames_processed": processed, "frames_dropped_stale": stale, "frames_lost_upstream": lost,
        "fps": round(processed / seconds, 2) if seconds > 0 else None,
        "latency_p50_ms": t.get("latency", {}).get("p50_ms"),
        "latency_p99_ms": t.get("latency", {}).get("p99_ms"),
        "frame_total_p50_ms": t.get("frame_total", {}).get("p50_ms"),
        "frame_total_p99_ms": t.get("frame_total", {}).get("p99_ms"),
        "peak_rss_mb": round(rss_kb / 1024.0, 1) if rss_kb else None,
        "stage_overruns": c.get("stage_overrun", 0),
        "tracked_fraction_live": s.get("tracked_fraction"),
        "stages": {k: {"p50_ms": v.get("p50_ms"), "p99_ms": v.get("p99_ms"), "mean_ms": v.get("mean_ms")}
                   for k, v in t.items() if k not in ("latency",)},
    }
for item in sys.argv[4:]:
    name, n = item.rsplit(":", 1)
    n = int(n)
    base = os.path.join(out, name)
    entry = {}
    for i, rate in enumerate(rates):
        f = run_figures(os.path.join(base, f"{rate}hz"), n, rate)
        if i == 0:
            entry.update(f or {"error": "no summary"})
        else:
            entry[f"at_{rate}hz"] = f
    try:
        t0, t1 = (float(x) for x in open(os.path.join(base, "lockstep", "wall.txt")).read().split())
        ls = json.load(open(os.path.join(base, "lockstep", "result", "summary.json")))
        entry["lockstep_fps"] = round(ls.get("frames", 0) / (t1 - t0), 2)
        entry["lockstep_frame_total_p50_ms"] = ls["timings"]["frame_total"]["p50_ms"]
        entry["lockstep_frame_total_p99_ms"] = ls["timings"]["frame_total"]["p99_ms"]
    except (OSError, ValueError, KeyError, ZeroDivisionError):
        entry["lockstep_fps"] = None
    report[name] = entry
    print(f"{name} ({n} frames, 640x480):")
    for rate in rates:
        f = entry if rate == rates[0] else entry.get(f"at_{rate}hz")
        if not f or "fps" not in f:
            print(f"  {rate} Hz: no result")
            continue
        print(f"  {rate} Hz live: {f['fps']} fps processed ({f['frames_processed']} of {f['frames_sent']} sent; "
              f"{f['frames_dropped_stale']} stale drops, {f['frames_lost_upstream']} lost upstream); latency p50 "
              f"{f['latency_p50_ms']} ms p99 {f['latency_p99_ms']} ms; frame p50 {f['frame_total_p50_ms']} p99 "
              f"{f['frame_total_p99_ms']} ms; peak RSS {f['peak_rss_mb']} MB")
        print("    stages p50/p99 ms: " + ", ".join(
            f"{k} {v['p50_ms']}/{v['p99_ms']}" for k, v in f["stages"].items() if k != "frame_total"))
    print(f"  lockstep (every frame, inline BA): {entry.get('lockstep_fps')} fps")
print(json.dumps(report))
PY
