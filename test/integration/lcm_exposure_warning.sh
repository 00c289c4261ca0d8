#!/usr/bin/env bash
# Every process that opens an LCM URL warns on stderr when the URL is udpm:// with
# ttl > 0, whatever its log level. The URL's address (300.0.0.1) is not an address:
# LCM refuses it before creating any socket, so the processes stop right after the
# warning and nothing touches the network.
set -uo pipefail
bin="${MBSLAM_BIN_DIR:?}"
url='udpm://300.0.0.1:7667?ttl=1'
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

check() {  # check NAME ARGS...
  local name="$1"
  shift
  if [[ ! -x "$bin/$name" ]]; then
    echo "skip $name: not built"
    return
  fi
  timeout 60 "$bin/$name" "$@" >"$work/$name.out" 2>"$work/$name.err"
  local status=$?
  if grep -q "WARNING: LCM URL '$url' has ttl > 0" "$work/$name.err"; then
    echo "ok   $name warns (exit $status)"
  else
    echo "FAIL $name printed no ttl warning (exit $status); stderr:"
    cat "$work/$name.err"
    failures=$((failures + 1))
  fi
}

check perception_service --lcm-url "$url" --set service.log_level=error
check viewer --lcm-url "$url" --out "$work/viewer" --set viewer.log_level=error
check planner_example --lcm-url "$url" --waypoints '0 0 0 0; 1 1 0 0'
check camera_driver --source folder --input "$work/none" --lcm-url "$url" --quiet
check odometry_bridge --input csv --file "$work/none.csv" --lcm-url "$url" --quiet
# A local URL: no warning.
if [[ -x "$bin/planner_example" ]]; then
  "$bin/planner_example" --lcm-url 'udpm://300.0.0.1:7667?ttl=0' --waypoints '0 0 0 0' \
    >/dev/null 2>"$work/local.err"
  if grep -q "WARNING: LCM URL" "$work/local.err"; then
    echo "FAIL planner_example warns for ttl=0"
    failures=$((failures + 1))
  fi
fi
exit $((failures > 0))
