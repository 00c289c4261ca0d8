#!/usr/bin/env bash
# fuzz: every fuzz target (test/fuzz) under libFuzzer + ASan + UBSan for N seconds each; executions and crashes per target
#
# Usage: scripts/eval.sh fuzz [SECONDS]   (default 60 per target)
# Builds the clang fuzz build in build-fuzz/ (MBSLAM_BUILD_FUZZ=ON; $MBSLAM_FUZZ_BUILD
# overrides the folder), then runs each target from its seed corpora plus the corpus
# kept from earlier runs (build-fuzz/fuzz/long/<target>/corpus). A crash, leak, timeout
# or out-of-memory stops that target and leaves its input in
# build-fuzz/fuzz/long/<target>/artifacts/ (reproduce: build-fuzz/fuzz/<target> FILE).
# Last line: {"seconds_per_target", "targets": {name: {"execs", "crashes", "corpus",
# "exec_per_s"}}, "total_execs", "total_crashes"}.
# eval: own-build
set -euo pipefail
root="${MBSLAM_ROOT:-$(cd "$(dirname "$0")/../.." && pwd)}"
out="${MBSLAM_EVAL_OUT:-$root/out/eval/fuzz}"
build="${MBSLAM_FUZZ_BUILD:-$root/build-fuzz}"
seconds="${1:-60}"
jobs="${JOBS:-2}"
mkdir -p "$out"

if ! command -v clang++ >/dev/null; then
  echo "fuzz: clang++ not found (scripts/install-deps.sh installs clang)" >&2
  exit 1
fi
echo "fuzz: building the clang fuzz build in $build (log: $out/build.log)" >&2
if ! { cmake -S "$root" -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
         -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMBSLAM_BUILD_FUZZ=ON -DMBSLAM_BUILD_TESTS=ON \
         -DMBSLAM_BUILD_BENCH=OFF -DMBSLAM_BUILD_DRIVERS=ON -DMBSLAM_BUILD_TOOLS=ON &&
       cmake --build "$build" -j"$jobs" --target fuzz_all; } >"$out/build.log" 2>&1; then
  echo "fuzz: build failed; the end of $out/build.log:" >&2
  tail -20 "$out/build.log" >&2
  exit 1
fi

manifest="$build/fuzz/targets.tsv"
results="$out/results.tsv"
: >"$results"
while IFS=$'\t' read -r name binary seeds; do
  [[ -n "$name" ]] || continue
  work="$build/fuzz/long/$name"
  log="$out/$name.log"
  before=$(ls "$work/artifacts" 2>/dev/null | wc -l || true)
  IFS=',' read -r -a seed_dirs <<<"$seeds"
  status=0
  "$root/test/fuzz/run_fuzz_target.sh" "$binary" "$seconds" 0 "$work" "${seed_dirs[@]}" \
    >"$log" 2>&1 || status=$?
  after=$(ls "$work/artifacts" 2>/dev/null | wc -l || true)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  corpus=$(find "$work/corpus" -type f | wc -l)
  crashes=$((after - before))
  if [[ $status -ne 0 && $crashes -eq 0 ]]; then crashes=1; fi  # died without an artifact
  printf '%s\t%s\t%s\t%s\t%s\n' "$name" "${execs:-0}" "$crashes" "$corpus" "${rate:-0}" >>"$results"
  printf 'fuzz: %-24s %10s execs  %6s/s  corpus %5s  crashes %s\n' "$name" "${execs:-0}" \
    "${rate:-0}" "$corpus" "$crashes" >&2
  if [[ $crashes -gt 0 ]]; then
    echo "fuzz: $name crashed; see $log and $work/artifacts/" >&2
    grep -m3 -E "ERROR: |runtime error|property violated" "$log" >&2 || true
  fi
done <"$manifest"

python3 - "$results" "$seconds" <<'PY'
import json, sys
path, seconds = sys.argv[1], float(sys.argv[2])
targets = {}
for line in open(path):
    name, execs, crashes, corpus, rate = line.rstrip("\n").split("\t")
    targets[name] = {"execs": int(execs), "crashes": int(crashes), "corpus": int(corpus),
                     "exec_per_s": int(rate)}
total_execs = sum(t["execs"] for t in targets.values())
total_crashes = sum(t["crashes"] for t in targets.values())
print(f"fuzz: {len(targets)} targets x {seconds:g} s: {total_execs} executions, "
      f"{total_crashes} crashes")
print(json.dumps({"seconds_per_target": seconds, "targets": targets,
                  "total_execs": total_execs, "total_crashes": total_crashes}))
PY
