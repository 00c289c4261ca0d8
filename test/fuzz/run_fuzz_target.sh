#!/usr/bin/env bash
# Runs one fuzz target (libFuzzer, or the replay driver of a gcc build) over its seed
# corpora for a bounded time. Used by CTest (test/fuzz/CMakeLists.txt) and by
# scripts/eval.d/fuzz.sh.
#
#   run_fuzz_target.sh BINARY SECONDS RUNS WORK_DIR [--fresh] SEED_DIR...
#
# SECONDS bounds the run (-max_total_time), RUNS the executions after the corpus
# (0 = unbounded). WORK_DIR/corpus keeps the inputs libFuzzer finds (emptied first
# with --fresh); a crash leaves its input in WORK_DIR/artifacts/. Seed folders that do
# not exist are skipped. Extra libFuzzer flags: $MBSLAM_FUZZ_FLAGS.
set -euo pipefail
if [[ $# -lt 4 ]]; then
  echo "usage: run_fuzz_target.sh BINARY SECONDS RUNS WORK_DIR [--fresh] SEED_DIR..." >&2
  exit 2
fi
binary="$1" seconds="$2" runs="$3" work="$4"
shift 4
if [[ "${1:-}" == "--fresh" ]]; then
  rm -rf "$work/corpus"
  shift
fi
mkdir -p "$work/corpus" "$work/artifacts"
seeds=()
for d in "$@"; do
  [[ -d "$d" ]] && seeds+=("$d")
done
flags=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512
       -artifact_prefix="$work/artifacts/" -print_final_stats=1)
[[ "$runs" != 0 ]] && flags+=(-runs="$runs")
# UBSan stops at the first report (built with -fno-sanitize-recover); show where.
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"
# shellcheck disable=SC2086
exec "$binary" "${flags[@]}" ${MBSLAM_FUZZ_FLAGS:-} "$work/corpus" "${seeds[@]}"
