#!/usr/bin/env bash
# generates every simulator scenario at 640x480 (sequence folders + LCM logs) and reports frames per second
#
# Usage: scripts/eval.sh sim-generate [FRAMES [SCENARIO...]]   (default: 300 frames, every scenario)
# Writes $MBSLAM_EVAL_OUT/<scenario>/ and prints a summary and, as the last line, one
# JSON object with the generator's frames per second per scenario (rendering only, and
# rendering + writing files and log) and the image coverage of the moving bodies.
set -euo pipefail
root="${MBSLAM_ROOT:-$(cd "$(dirname "$0")/../.." && pwd)}"
bin="${MBSLAM_BIN:-$root/build/bin}"
out="${MBSLAM_EVAL_OUT:-$root/out/eval/sim-generate}"
frames="${1:-300}"
shift || true
mkdir -p "$out"
if [[ ! -x "$bin/mbslam-sim" ]]; then
  echo "sim-generate: $bin/mbslam-sim not built" >&2
  exit 1
fi

json_get() {
  grep -o "\"$2\": [^,}]*" "$1" | head -1 | sed 's/.*: //'
}

render_json=""
total_json=""
coverage_json=""
min_render=""
echo "== $frames frames per scenario at 640x480 into $out"
scenarios=("$@")
if [[ ${#scenarios[@]} -eq 0 ]]; then
  mapfile -t scenarios < <("$bin/mbslam-sim" --list | awk '{print $1}')
fi
for s in "${scenarios[@]}"; do
  "$bin/mbslam-sim" --quiet --scenario "$s" --size 640x480 --frames "$frames" --out "$out/$s" --json "$out/$s.json"
  f="$out/$s.json"
  render=$(json_get "$f" render_fps)
  total=$(json_get "$f" total_fps)
  setup=$(json_get "$f" setup_s)
  cov=$(json_get "$f" mean_moving_fraction)
  vis=$(grep -o '"frames_visible": \[[^]]*\]' "$f" | sed 's/.*: //')
  printf "  %-18s render %6.1f frames/s, with writing %6.1f frames/s, set-up %5.1f s, movers cover %5.1f %% of the image, frames visible per mover %s\n" \
    "$s" "$render" "$total" "$setup" "$(awk -v c="$cov" 'BEGIN { print 100 * c }')" "$vis"
  render_json+="\"$s\": $render, "
  total_json+="\"$s\": $total, "
  coverage_json+="\"$s\": $cov, "
  if [[ -z "$min_render" ]] || awk -v a="$render" -v b="$min_render" 'BEGIN { exit !(a < b) }'; then
    min_render="$render"
  fi
done
echo "{\"frames\": $frames, \"width\": 640, \"height\": 480, \"min_render_fps\": $min_render, \"render_fps\": {${render_json%, }}, \"total_fps\": {${total_json%, }}, \"mean_moving_fraction\": {${coverage_json%, }}}"
