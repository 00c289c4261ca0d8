#!/usr/bin/env bash
# Installs what is missing, builds, and runs the test suite (everything except the
# labels `slow` and `fuzz`, which run on request).
#
#   scripts/test.sh                 default suite (unit + integration)
#   scripts/test.sh -L slow         only tests with a label (CTest -L regex)
#   scripts/test.sh --asan          the unit tests under AddressSanitizer + UBSan (build-asan/)
#   scripts/test.sh --all           every label, slow and fuzz included
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)

./scripts/install-deps.sh

mode=default
ctest_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --asan) mode=asan; shift ;;
    --all) mode=all; shift ;;
    -L) ctest_args+=(-L "$2"); mode=label; shift 2 ;;
    *) echo "test.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done

build_dir=build
cmake_extra=()
if [[ "$mode" == asan ]]; then
  build_dir=build-asan
  cmake_extra+=(-DMBSLAM_SANITIZE=ON -DMBSLAM_BUILD_BENCH=OFF)
  export BUILD_TYPE=RelWithDebInfo
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest_args+=(-L unit)
fi
./scripts/build.sh "$build_dir" "${cmake_extra[@]}"

case "$mode" in
  default) ctest_args+=(-LE "slow|fuzz") ;;
  all) ;;
esac

cd "$build_dir"
status=0
ctest --output-on-failure --timeout 900 -j2 "${ctest_args[@]}" || status=$?
echo "test.sh: finished in $(( $(date +%s) - start )) s with status $status"
exit $status
