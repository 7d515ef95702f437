#!/usr/bin/env bash
# A local Ray cluster in a new network namespace NS with only lo up (usage statistics
# off): a head with HEAD_CPUS and, unless WORKER_CPUS is 0, a worker node; runs the
# command inside the namespace, then kills that namespace's processes (by id) and
# deletes it, whatever happens. Root only. RAY names the ray command (default: ray).
# usage: ray_local_cluster.sh NS HEAD_CPUS WORKER_CPUS -- command...
set -euo pipefail
ns=$1; hc=$2; wc=$3; shift 4
export RAY_USAGE_STATS_ENABLED=0
ray=${RAY:-ray}
tmp=$(mktemp -d /tmp/unfray.XXXX)
cleanup() {
  for p in $(ip netns pids "$ns" 2>/dev/null); do kill -9 "$p" 2>/dev/null || true; done
  sleep 1
  ip netns del "$ns" 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
ip netns add "$ns"
ip netns exec "$ns" ip link set lo up
ip netns exec "$ns" "$ray" start --head --port=6379 --node-ip-address=127.0.0.1 --num-cpus="$hc" \
  --disable-usage-stats --include-dashboard=false --temp-dir="$tmp" > /dev/null
if [[ $wc -gt 0 ]]; then
  ip netns exec "$ns" "$ray" start --address=127.0.0.1:6379 --node-ip-address=127.0.0.1 --num-cpus="$wc" \
    --disable-usage-stats > /dev/null
fi
ip netns exec "$ns" "$@"
