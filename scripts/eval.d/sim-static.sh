#!/usr/bin/env bash
# Scenario 'static': whole pipeline, camera ATE / path length, fraction tracked, moving-feature segmentation
set -euo pipefail
source "$(dirname "$0")/_scenario.sh"
ABLATION=0 eval_scenario static "${1:-300}"
