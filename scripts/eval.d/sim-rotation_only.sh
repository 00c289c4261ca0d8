#!/usr/bin/env bash
# Scenario 'rotation_only': whole pipeline, camera ATE / path length, fraction tracked, moving-feature segmentation
set -euo pipefail
source "$(dirname "$0")/_scenario.sh"
ABLATION=0 eval_scenario rotation_only "${1:-300}"
