#!/usr/bin/env bash
# `navbus foxglove` under DDS Security (domain 116): navbus-filter runs secure with the filter
# identity; one bridge runs with the tool identity (the secure loopback profile; its grant reads
# every topic and writes only its health) and must serve the filter's answer to an operator's
# command (sent secure with the operator identity) to a Foxglove client; a second bridge on the
# plain profile, without credentials, must see none of it.
# Usage: run_bridge_secure.sh BUILD_DIR SOURCE_DIR. KEEP_WORK=1 keeps the scratch directory.
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
bin=$build/bin
MCAP_TEST_NAME=foxglove-secure
source "$src/tests/mcap/common.sh"
[ -f "$build/security/tool/key.pem" ] ||
  fail "no credentials in $build/security (scripts/make_credentials.sh, run by the build)"
install_node_readers
cp "$src/tests/foxglove/first_message.mjs" "$node_dir/"
domain=116
secure=navbus_participant_udp_loopback_secure
printf '%s\n' "extends: $src/config/filter_demo.yaml" "domain_id: $domain" \
  "participant_profile: $secure" "security_identity: $build/security/filter" \
  "fault_monitor: {judged_from_start: false}" > "$work/filter.yaml"  # no fault manager here
"$bin/navbus-filter" -c "$work/filter.yaml" > "$work/filter.log" 2>&1 &
pids+=($!)
"$bin/navbus" -d $domain --profile $secure --identity "$build/security/tool" foxglove --port 0 \
  > "$work/secure_bridge.log" 2>&1 &
secure_bridge=$!
"$bin/navbus" -d $domain --profile navbus_participant_udp_loopback foxglove --port 0 \
  > "$work/plain_bridge.log" 2>&1 &
plain_bridge=$!
pids+=($secure_bridge $plain_bridge)
port_of() {
  local deadline=$((SECONDS + 60)) port=""
  until port=$(grep -o "ws://127.0.0.1:[0-9]*" "$1" | head -1 | cut -d: -f3) && [ -n "$port" ]; do
    [ $SECONDS -lt $deadline ] || fail "no bridge listening in $1"
    sleep 0.1
  done
  echo "$port"
}
secure_port=$(port_of "$work/secure_bridge.log")
plain_port=$(port_of "$work/plain_bridge.log")
# Both bridges' clients wait for the filter's answer to an operator's command (secure, with the
# operator identity): only the secure bridge may carry it.
(cd "$node_dir" && node first_message.mjs "ws://127.0.0.1:$secure_port" \
  navbus/nav/command_outcome 40) > "$work/secure_client.log" 2>&1 &
secure_client=$!
(cd "$node_dir" && node first_message.mjs "ws://127.0.0.1:$plain_port" \
  navbus/nav/command_outcome 10) > "$work/plain_client.log" 2>&1 &
plain_client=$!
pids+=($secure_client $plain_client)
deadline=$((SECONDS + 60))
until grep -q "^subscribed to navbus/nav/command_outcome" "$work/secure_client.log" &&
  grep -q "^connected" "$work/plain_client.log"; do
  [ $SECONDS -lt $deadline ] || fail "the clients did not connect and subscribe within 60 s"
  sleep 0.1
done
"$bin/navbus" -d $domain --profile $secure --identity "$build/security/operator" \
  command EXCLUDE_SATELLITE --sv 7 --issuer operator > "$work/command.log" 2>&1 ||
  fail "the operator's command: $(cat "$work/command.log")"
grep -q "vehicle 1: APPLIED" "$work/command.log" || fail "not applied: $(cat "$work/command.log")"
wait $secure_client || fail "the secure bridge: $(cat "$work/secure_client.log")"
cat "$work/secure_client.log"
if wait $plain_client; then
  fail "the bridge without credentials carried the secure filter's answer"
fi
grep -q "navbus/nav/solution" "$work/plain_client.log" &&
  fail "the bridge without credentials advertised the secure filter's solution"
echo "without credentials: $(head -1 "$work/plain_client.log")"
echo "foxglove secure: ok"
