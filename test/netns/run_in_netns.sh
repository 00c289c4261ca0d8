#!/usr/bin/env bash
# Runs a command inside a private network namespace with only loopback, multicast
# routed to lo. The ONLY place this project uses LCM's udpm:// multicast.
#
#   test/netns/run_in_netns.sh CMD [ARGS...]
#
# Exit code 77 (CTest's skip code) when namespaces cannot be created here.
set -euo pipefail
if [[ "${1:-}" == "--inside" ]]; then
  shift
  ip link set lo up
  ip route add 224.0.0.0/4 dev lo 2>/dev/null || true
  # Refuse to run if anything but loopback is visible.
  if ip -o link | grep -v ': lo:' | grep -q .; then
    echo "run_in_netns: namespace has interfaces besides lo; refusing" >&2
    exit 1
  fi
  exec "$@"
fi
if ! command -v unshare >/dev/null || ! command -v ip >/dev/null; then
  echo "run_in_netns: unshare or ip missing; skipping" >&2
  exit 77
fi
unshare_flags=(-n)
if [[ $(id -u) -ne 0 ]]; then unshare_flags=(-r -n); fi
if ! unshare "${unshare_flags[@]}" true 2>/dev/null; then
  echo "run_in_netns: cannot create a network namespace here (unshare refused); skipping" >&2
  exit 77
fi
exec unshare "${unshare_flags[@]}" "$0" --inside "$@"
