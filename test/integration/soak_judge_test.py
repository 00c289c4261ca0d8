#!/usr/bin/env python3
"""The soak judge (soak_judge.py) on synthetic monitor CSVs whose verdict is known.

  soak_judge_test.py   (exit 0 when every case gets the expected verdict)
"""
import json, math, os, subprocess, sys, tempfile

JUDGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "soak_judge.py")
COLUMNS = ("t_s,rss_mb,frames_received,frames_processed,frames_dropped,map_points,map_keyframes,"
           "map_observations,occupancy_bytes,occupancy_mem_bytes,trajectory_poses,heap_in_use_mb,heap_held_mb,"
           "results_kept_mb")

def run(name, rss, heap, kept=lambda m: 0.002 * 60 * m, minutes=20, heap_columns=True):
    """A 20-minute run sampled every 5 s; rss, heap, kept: MB as functions of the minute."""
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "rss.csv")
        with open(path, "w") as f:
            cols = COLUMNS if heap_columns else ",".join(COLUMNS.split(",")[:11])
            f.write(cols + "\n")
            for k in range(minutes * 12 + 1):
                t = 5.0 * k
                m = t / 60.0
                row = [f"{t:.1f}", f"{rss(m):.3f}", str(30 * int(t)), str(30 * int(t)), "0", "2000", "40", "10000",
                       "0", "0", str(int(1800 * m))]
                if heap_columns:
                    row += [f"{heap(m):.3f}" if k > 0 else "-1", f"{heap(m) + 15:.3f}" if k > 0 else "-1",
                            f"{kept(m):.3f}" if k > 0 else "-1"]
                f.write(",".join(row) + "\n")
        p = subprocess.run([sys.executable, JUDGE, path, str(minutes), "0.5", "1", "0", "0", "null", "synthetic"],
                           capture_output=True, text=True)
        verdict = json.loads(p.stdout.strip().splitlines()[-1])
        assert (p.returncode == 0) == verdict["passed"], (name, p.returncode, verdict)
        return verdict

failures = []
def expect(name, verdict, passed):
    ok = verdict["passed"] == passed
    print(f"{'ok  ' if ok else 'FAIL'} {name}: passed={verdict['passed']} rss beyond map "
          f"{verdict['rss_slope_beyond_map_mb_per_min']} heap beyond {verdict.get('heap_in_use_slope_beyond_map_mb_per_min')}")
    if not ok:
        failures.append(name)

# Steady memory with a 20 MB swing within each minute (bundle adjustment, buffers): passes.
wobble = lambda m: 10.0 * (1.0 + math.sin(2.0 * math.pi * 7.3 * m))
expect("steady", run("steady", lambda m: 100.0 + wobble(m), lambda m: 25.0 + 0.3 * wobble(m)), True)
# The recorder's own growth (kept for the output files, reported) is not a leak.
expect("recorder grows", run("recorder grows", lambda m: 100.0 + 0.3 * m + wobble(m),
                             lambda m: 25.0 + 0.3 * m, kept=lambda m: 0.3 * m), True)
# A leak: heap in use and RSS grow 1 MB/min beyond what is accounted for.
expect("leak", run("leak", lambda m: 100.0 + 1.0 * m + wobble(m), lambda m: 25.0 + 1.0 * m), False)
# A leak the RSS does not show (freed memory reused): the heap in use catches it.
expect("leak hidden in the RSS", run("hidden", lambda m: 100.0 + wobble(m), lambda m: 25.0 + 1.0 * m), False)
# The allocator holding more (RSS up 1 MB/min, heap in use flat) still fails: the
# machine gives up that memory.
expect("RSS growth without a leak", run("rss", lambda m: 100.0 + 1.0 * m, lambda m: 25.0), False)
# The last sample alone in a minute of its own (t = 20.0 min) at a swing's high is no
# minute's minimum: it must not decide the trend.
spike = lambda m: 100.0 + (30.0 if m > 19.99 else 0.0) + (wobble(m) if m < 19.99 else 0.0)
expect("a last partial minute", run("partial", spike, lambda m: 25.0), True)
# Older CSVs without the heap columns: judged on the RSS alone.
old = run("old csv", lambda m: 100.0 + wobble(m), lambda m: 0.0, heap_columns=False)
expect("an older CSV", old, True)
if old.get("heap_slope_judged"):
    failures.append("older CSV: heap judged without figures")

n = 7
print(f"{n - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
