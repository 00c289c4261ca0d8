#!/usr/bin/env bash
# Bearing-only tracking cue ablation (thesis fig. 6.6) on synthetic following / crossing scenes: depth sigma per cue set, plot, position and scale error, volume hit rates
set -euo pipefail
exec "$MBSLAM_BIN/mbslam-bot-ablation" --out "$MBSLAM_EVAL_OUT" "$@"
