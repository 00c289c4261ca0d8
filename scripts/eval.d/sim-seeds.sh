#!/usr/bin/env bash
# Scenario evaluations over several renderings (texture seeds) of the same scenes: mean, min and max of each key, so that a figure is not one rendering's luck
#
#   scripts/eval.sh sim-seeds [--scenarios "crossing following multi"] [--seeds "1 2 3"]
#                             [--ransac-seeds "24301 1 2"]
#   (env SERVICE_ARGS="--set a.b=v ..." passes options to the service)
#
# SIM_SEED changes the textures and with them the features; the geometry, the motions and
# the truth stay. --ransac-seeds runs each rendering once per listed seed of the
# segmentation's essential-matrix RANSAC (segmentation.two_view.ransac_seed; list 24301,
# the default, to include the usual run): the same images, other draws of the
# segmentation (SLAM's own essential-matrix fits keep theirs). Each run is the scenario's own
# evaluation (sim-NAME), in lockstep; outputs in MBSLAM_EVAL_OUT/NAME-seedS/ (with RANSAC
# seeds NAME-seedS-ransacR/). JSON (last line): {"NAME": {"KEY": {"mean", "min", "max",
# "values"}, ...}, ...} over the keys below; a key a run could not compute is left out of
# that run's values.
set -euo pipefail
source "$(dirname "$0")/_lib.sh"
scenarios="crossing following multi"
seeds="1 2 3"
ransac_seeds=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --scenarios) scenarios="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --ransac-seeds) ransac_seeds="$2"; shift 2 ;;
    *) echo "sim-seeds: unknown argument $1" >&2; echo '{}'; exit 2 ;;
  esac
done
results=()
# Whole numbers in the service's range, each once (blank = the default run only).
checked=""
for r in $ransac_seeds; do
  if ! [[ "$r" =~ ^(0|[1-9][0-9]{0,9})$ ]] || (( r > 4294967295 )); then
    echo "sim-seeds: --ransac-seeds takes whole numbers 0-4294967295 ($r)" >&2; echo '{}'; exit 2
  fi
  [[ " $checked " == *" $r "* ]] || checked="${checked:+$checked }$r"
done
ransac_seeds="$checked"
for name in $scenarios; do
  for seed in $seeds; do
    for ransac in ${ransac_seeds:-default}; do
      out="$MBSLAM_EVAL_OUT/$name-seed$seed"
      label="$seed"
      args="${SERVICE_ARGS:-}"
      if [[ "$ransac" != default ]]; then
        out="$out-ransac$ransac"
        label="$seed/$ransac"
        args="$args --set segmentation.two_view.ransac_seed=$ransac"
      fi
      mkdir -p "$out"
      echo "== sim-$name, texture seed $seed${ransac_seeds:+, RANSAC seed $ransac}" >&2
      line=$(SIM_SEED="$seed" SERVICE_ARGS="$args" MBSLAM_EVAL_OUT="$out" "$MBSLAM_ROOT/scripts/eval.d/sim-$name.sh" \
        2>"$out/eval.log" | tail -1) || true
      [[ "$line" == "{"* ]] || line="{}"
      echo "$line" >"$out/result.json"
      results+=("$name" "$label" "$out/result.json")
    done
  done
done
python3 - "${results[@]}" <<'PY'
import json, sys
keys = ["ate_rel_path", "tracked_fraction", "tracked_fraction_live", "scale_error", "moving_recall", "moving_precision",
        "moving_recall_off_silhouette", "moving_precision_off_silhouette", "object_pos_err_rel_2s",
        "relative_scale_error", "predicted_hit_rate_0_5s", "predicted_hit_rate_1s",
        "predicted_hit_rate_0_5s_all_estimates", "predicted_hit_rate_1s_all_estimates",
        "predicted_overlap_rate_1s_all_estimates",
        "object_samples_matched_share", "object_samples_phantom_share", "occupancy_precision",
        "occupancy_recall", "object_traj_err_rel", "object_shape_err_rel", "object_shape_translated_err_rel",
        "track_misclassification",
        "ate_rel_path_no_feedback", "feedback_ablation_ratio", "moving_recall_epipolar_only"]
args = sys.argv[1:]
runs = {}
for i in range(0, len(args), 3):
    name, seed, path = args[i], args[i + 1], args[i + 2]
    try:
        d = json.load(open(path))
    except Exception:
        d = {}
    # The segmentation-feedback ablation (sim-multi): the ATE without it over the ATE with it.
    nf, ate = d.get("ate_rel_path_no_feedback"), d.get("ate_rel_path")
    if isinstance(nf, (int, float)) and isinstance(ate, (int, float)) and ate > 0:
        d["feedback_ablation_ratio"] = nf / ate
    runs.setdefault(name, []).append((seed, d))
out = {}
for name, rs in runs.items():
    agg = {}
    with_ransac = any("/" in s for s, _ in rs)
    print(f"sim-{name} over texture seeds{' / RANSAC seeds' if with_ransac else ''} {' '.join(s for s, _ in rs)}:")
    for k in keys:
        vals = [d[k] for _, d in rs if isinstance(d.get(k), (int, float))]
        if not vals:
            continue
        agg[k] = {"mean": sum(vals) / len(vals), "min": min(vals), "max": max(vals), "values": vals}
        print(f"  {k:26s} mean {agg[k]['mean']:.4g}  min {min(vals):.4g}  max {max(vals):.4g}  ({', '.join(f'{v:.4g}' for v in vals)})")
    out[name] = agg
print(json.dumps(out))
PY
