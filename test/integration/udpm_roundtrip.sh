#!/usr/bin/env bash
# Inside a private network namespace (see test/netns/run_in_netns.sh):
#  1. every message type between two processes over udpm://, byte-identical;
#  2. lcm-logplayer replays a recorded log and a subscriber receives every message.
set -euo pipefail
bin="${MBSLAM_BIN_DIR:?}"
tool="$bin/../tests/lcm_roundtrip_tool"
url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "== process-to-process over udpm"
"$tool" subscribe "$url" 101 5 20 >"$work/sub1.out" &
sub=$!
sleep 0.5
"$tool" publish "$url" 101 5
wait $sub
cat "$work/sub1.out"

echo "== lcm-logplayer replay over udpm"
"$tool" write-log "$work/all.lcmlog" 202 5
"$tool" subscribe "$url" 202 5 30 >"$work/sub2.out" &
sub=$!
sleep 0.5
lcm-logplayer --lcm-url="$url" --speed=1 "$work/all.lcmlog"
wait $sub
cat "$work/sub2.out"
echo "udpm round trips OK"
