#!/usr/bin/env bash
# A lockstep replay of the same log twice produces byte-identical output logs, whatever
# the machine's load: the second run's bundle adjustments get a time limit of 1 µs,
# which a lockstep replay ignores (it stops on iterations only).
set -euo pipefail
bin="${MBSLAM_BIN_DIR:?}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
input="${1:-}"
if [[ -z "$input" ]]; then
  "$bin/../tests/make_test_log" "$work/in.lcmlog" --frames 90 --faults
  input="$work/in.lcmlog"
fi
for run in 1 2; do
  limit=()
  if [[ "$run" == 2 ]]; then limit=(--set slam.ba.max_seconds=0.000001); fi
  "$bin/perception_service" --lcm-url "file://$input?speed=0" --mode lockstep \
    --output-log "$work/out$run.lcmlog" --set service.log_level=warning "${limit[@]}" 2>"$work/run$run.err"
done
size=$(stat -c %s "$work/out1.lcmlog")
if [[ "$size" -lt 1000 ]]; then
  echo "output log suspiciously small ($size bytes)"; cat "$work/run1.err"; exit 1
fi
if cmp "$work/out1.lcmlog" "$work/out2.lcmlog"; then
  echo "lockstep replays identical: $size bytes, $(md5sum < "$work/out1.lcmlog" | cut -c1-12)"
else
  echo "lockstep replays differ"; exit 1
fi
