#!/usr/bin/env bash
# The compose demo without Docker: the installed package (what the runtime image holds), one
# network namespace per service (filter, fault-manager, simulator, recorder) on a bridge, each
# running the compose file's command (bin/navbus-demo-participant ROLE) with the compose file's
# environment (docker/demo.env). Every participant must stop by itself, and the summary service's
# report must show both faults decided and the figures written.
# Usage: run_compose_topology.sh BUILD_DIR SOURCE_DIR. Exits 77 where namespaces are not permitted.
set -euo pipefail
build=$1 src=$2
id=$$
# shellcheck source=namespaces.sh
source "$src/tests/netns/namespaces.sh"
netns_available

hosts=(filter fm sim rec)
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  netns_delete "$id" "${hosts[@]}"
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; cat "$work/out/"*.log 2>/dev/null | tail -80; exit 1; }

cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
participant=$work/prefix/bin/navbus-demo-participant
set -a
# shellcheck source=../../docker/demo.env
source "$src/docker/demo.env"
set +a
export NAVBUS_OUT=$work/out   # the compose file's bind mount
netns_create "$id" 79 "${hosts[@]}"
echo "namespaces: ${hosts[*]}; domain $NAVBUS_DOMAIN, profile $NAVBUS_PROFILE (docker/demo.env)"

start() {  # host role
  ip netns exec "nb$1$id" "$participant" "$2" > /dev/null 2>&1 &
  pids+=($!)
}
start filter filter
start fm fault-manager
start rec recorder
start sim simulator
deadline=$((SECONDS + 150))
for i in "${!pids[@]}"; do
  while kill -0 "${pids[$i]}" 2>/dev/null; do
    [ $SECONDS -lt $deadline ] || fail "a participant did not stop by itself within 150 s"
    sleep 0.5
  done
  rc=0
  wait "${pids[$i]}" || rc=$?
  [ $rc -eq 0 ] || fail "participant ${hosts[$i]} exited $rc"
done
pids=()
echo "every participant stopped by itself"

"$participant" summary | tee "$work/summary.txt"
grep -q "navbus demo summary" "$work/summary.txt" || fail "no summary"
grep -q "filter: .*commands applied [1-9]" "$work/summary.txt" || fail "the filter applied no command"
ls "$work/out/figures/"*.png > /dev/null || fail "no figures"
echo "compose topology: ok"
