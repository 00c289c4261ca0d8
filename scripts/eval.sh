#!/usr/bin/env bash
# The one entry point for every benchmark and evaluation.
#
#   scripts/eval.sh list            what is registered, one line each
#   scripts/eval.sh NAME [args...]  builds if needed, runs NAME
#
# Each evaluation is a script scripts/eval.d/NAME.sh whose second line is a
# "# description". It prints a human summary and, as its LAST line, one JSON object
# with the figures. Evaluations find the build in $MBSLAM_BUILD (default build/) and
# write their outputs under $MBSLAM_EVAL_OUT (default out/eval/NAME/). A script with a
# line "# eval: own-build" builds what it needs itself (e.g. fuzz, in build-fuzz/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"

if [[ $# -lt 1 || "$1" == "list" || "$1" == "-h" || "$1" == "--help" ]]; then
  echo "usage: scripts/eval.sh NAME [args...]"
  echo "registered evaluations:"
  for f in scripts/eval.d/*.sh; do
    [[ -e "$f" ]] || continue
    name=$(basename "$f" .sh)
    [[ "$name" == _* ]] && continue  # helpers, not evaluations
    desc=$(sed -n '2s/^# *//p' "$f")
    printf "  %-24s %s\n" "$name" "$desc"
  done
  exit 0
fi

name="$1"
shift
script="scripts/eval.d/$name.sh"
if [[ "$name" == _* || ! -f "$script" ]]; then
  echo "eval.sh: no evaluation named '$name' (scripts/eval.sh list shows them)" >&2
  exit 2
fi

export MBSLAM_ROOT="$root"
export MBSLAM_BUILD="${MBSLAM_BUILD:-$root/build}"
export MBSLAM_BIN="$MBSLAM_BUILD/bin"
export MBSLAM_EVAL_OUT="${MBSLAM_EVAL_OUT:-$root/out/eval/$name}"
export MBSLAM_DATA="${MBSLAM_DATA:-$root/../shared/data}"
mkdir -p "$MBSLAM_EVAL_OUT"

if [[ "${MBSLAM_EVAL_NO_BUILD:-0}" != "1" ]]; then
  ./scripts/install-deps.sh >/dev/null
fi
if [[ "${MBSLAM_EVAL_NO_BUILD:-0}" != "1" ]] && ! grep -q '^# eval: own-build' "$script"; then
  ./scripts/build.sh "$MBSLAM_BUILD" >"$MBSLAM_EVAL_OUT/build.log" 2>&1 || {
    echo "eval.sh: build failed, see $MBSLAM_EVAL_OUT/build.log" >&2
    tail -20 "$MBSLAM_EVAL_OUT/build.log" >&2
    exit 1
  }
fi
exec bash "$script" "$@"
