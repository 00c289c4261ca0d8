#!/usr/bin/env bash
# Scenario 'following': whole pipeline, camera ATE / path length, fraction tracked, moving-feature segmentation with and without the Flow Vector Bound
set -euo pipefail
source "$(dirname "$0")/_scenario.sh"
ABLATION=0 FVB_ABLATION=1 eval_scenario following "${1:-300}"
