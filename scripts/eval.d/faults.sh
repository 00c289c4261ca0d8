#!/usr/bin/env bash
# Fault injection: per fault, survived / frames until tracking is back / PERCEPTION_STATUS counters
# Runs the fault-injection tests (test/integration/fault_injection_test.cc, and
# driver_restart_test.cc in a private network namespace) and collects the FAULT_JSON line
# each prints. JSON: {"faults": {name: {"survived", "frames_to_recover", "recovery_bound",
# "status_counter", ...}}, "tests_passed": bool}.
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
tests="$MBSLAM_BUILD/tests"
out="$MBSLAM_EVAL_OUT"
export MBSLAM_BIN_DIR="$MBSLAM_BIN"
export MBSLAM_FAULT_SEQUENCE="$out/sequence"  # made on first use, then reused
for t in fault_injection_test driver_restart_test; do
  if [[ ! -x "$tests/$t" ]]; then
    echo "faults: $tests/$t missing (build with MBSLAM_BUILD_TESTS=ON)" >&2
    echo '{}'
    exit 1
  fi
done
status_in=0
"$tests/fault_injection_test" >"$out/fault_injection.log" 2>&1 || status_in=$?
status_netns=0
"$MBSLAM_ROOT/test/netns/run_in_netns.sh" "$tests/driver_restart_test" >"$out/driver_restart.log" 2>&1 || status_netns=$?
python3 - "$out/fault_injection.log" "$out/driver_restart.log" "$status_in" "$status_netns" <<'PY'
import json, sys
faults = {}
for path in sys.argv[1:3]:
    for line in open(path, errors="replace"):
        if line.startswith("FAULT_JSON "):
            r = json.loads(line[len("FAULT_JSON "):])
            faults[r.pop("name")] = r
status_in, status_netns = int(sys.argv[3]), int(sys.argv[4])
skipped_netns = status_netns == 77
passed = status_in == 0 and status_netns in (0, 77)
print(f"{'fault':32s} {'survived':9s} {'recover':>8s} {'bound':>6s}  counters")
for name, r in faults.items():
    counters = ", ".join(f"{k} {v}" for k, v in r["status_counter"].items())
    print(f"{name:32s} {str(r['survived']):9s} {r['frames_to_recover']:8d} {r['recovery_bound']:6d}  {counters}")
if skipped_netns:
    print("driver_restart skipped: no network namespace here")
print(f"tests {'passed' if passed else 'FAILED'} (in-process exit {status_in}, netns exit {status_netns}); logs in {sys.argv[1].rsplit('/', 1)[0]}")
print(json.dumps({"faults": faults, "tests_passed": passed, "driver_restart_skipped": skipped_netns}))
sys.exit(0 if passed else 1)
PY
