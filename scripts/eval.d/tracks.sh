#!/usr/bin/env bash
# Motion segmentation scored on any folder of *.tracks.txt (--root DIR), both settings
set -euo pipefail
exec "$MBSLAM_BIN/mbslam-segment-tracks" --mode both "$@"
