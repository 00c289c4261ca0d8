#!/usr/bin/env bash
# Hopkins 155 motion segmentation: misclassification with the number of motions given and fully online
set -euo pipefail
root="${MBSLAM_DATA}/hopkins155"
if [[ ! -d "$root" ]]; then
  echo "hopkins155: $root not found (set MBSLAM_DATA)"; echo '{"skipped": true}'; exit 0
fi
"$MBSLAM_BIN/mbslam-segment-tracks" --root "$root" --mode both "$@" | tee "$MBSLAM_EVAL_OUT/hopkins155.txt"
