#!/usr/bin/env bash
# lcm-logplayer replays a camera_driver log over udpm:// inside a private network
# namespace (test/netns/run_in_netns.sh) and a subscriber receives every frame,
# byte-identical and in order. Exit 77 (skip) where namespaces cannot be created.
#
#   test/drivers/logplayer_netns_test.sh BIN_DIR TESTS_DIR   (from the repo root)
set -euo pipefail
bin_dir=$1
tests_dir=$2
logplayer=${LCM_LOGPLAYER:-lcm-logplayer}
command -v "$logplayer" >/dev/null || { echo "lcm-logplayer not installed; skipping" >&2; exit 77; }
work=$(mktemp -d -t mbslam_netns_XXXXXX)
trap 'rm -rf "$work"' EXIT

# 60 BGR frames of 320x240 (230 kB each) at 20 Hz: 3 s of replay.
"$tests_dir/make_test_images" "$work/images" 60 320 240
"$bin_dir/camera_driver" --quiet --no-progress --input "$work/images" --rate 20 \
  --log "$work/frames.lcmlog"

cat > "$work/inside.sh" <<INSIDE
set -euo pipefail
url='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
"$tests_dir/lcm_log_receiver" --url "\$url" --log "$work/frames.lcmlog" \
  --channel CAMERA_IMAGE --ready "$work/ready" --timeout 30 &
receiver=\$!
for _ in \$(seq 100); do [[ -e "$work/ready" ]] && break; sleep 0.05; done
[[ -e "$work/ready" ]] || { echo "receiver did not start" >&2; kill \$receiver; exit 1; }
"$logplayer" --speed 1 -l "\$url" "$work/frames.lcmlog"
wait \$receiver
INSIDE
# Not exec: the EXIT trap must still run to remove $work (the exit code, 77 included,
# passes through set -e).
test/netns/run_in_netns.sh bash "$work/inside.sh"
