#!/usr/bin/env bash
# A DDS application with Fast DDS's defaults sees navbus topics when the navbus participants use
# navbus_participant_udp_lan (multicast discovery on the host's interfaces), and does not under
# the default navbus_participant_udp_loopback (unicast discovery on 127.0.0.1 only, which keeps
# the bus off the network). Domain 63.
set -euo pipefail
bin=$1 peer=$2 scenarios=$3
domain=63
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
cat > "$work/sim.yaml" <<YAML
extends: $scenarios/default.yaml
timing: {min_readers: {imu: 1, raw_imu: 0, gnss: 0, star_tracker: 0}}
YAML
run() {  # profile, expected exit of the peer
  "$bin/navbus-sensor-sim" -c "$work/sim.yaml" -d "$domain" --profile "$1" --duration 4 > "$work/sim.log" 2>&1 &
  local sim=$! rc=0
  "$peer" "$domain" 20 3 || rc=$?
  kill "$sim" 2>/dev/null || true
  wait "$sim" 2>/dev/null || true
  [[ $rc == "$2" ]] || { echo "FAIL: profile $1: the default-QoS application exited $rc, expected $2"; cat "$work/sim.log"; exit 1; }
  echo "profile $1: default-QoS application exit $rc as expected"
}
run navbus_participant_udp_lan 0
run navbus_participant_udp_loopback 1
