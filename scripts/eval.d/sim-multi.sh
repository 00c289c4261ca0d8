#!/usr/bin/env bash
# Scenario 'multi': whole pipeline, camera ATE / path length, fraction tracked, moving-feature segmentation, feedback ablation
set -euo pipefail
source "$(dirname "$0")/_scenario.sh"
ABLATION=1 eval_scenario multi "${1:-300}"
