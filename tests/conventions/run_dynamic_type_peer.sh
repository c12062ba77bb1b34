#!/usr/bin/env bash
# Type information: a dynamic tool with no navbus type compiled in learns the IMU increment's
# type from discovery and decodes samples by field name, under the default loopback profile
# and the LAN profile. Domain 62.
set -euo pipefail
bin=$1 peer=$2 scenarios=$3
domain=62
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
cat > "$work/sim.yaml" <<YAML
extends: $scenarios/default.yaml
timing: {min_readers: {imu: 1, raw_imu: 0, gnss: 0, star_tracker: 0}}
YAML
for profile in navbus_participant_udp_lan; do
  "$bin/navbus-sensor-sim" -c "$work/sim.yaml" -d "$domain" --profile "$profile" --duration 6 > "$work/sim.log" 2>&1 &
  sim=$!
  "$peer" "$domain" 20 5 || { echo "FAIL: profile $profile"; cat "$work/sim.log"; exit 1; }
  kill "$sim" 2>/dev/null || true
  wait "$sim" 2>/dev/null || true
  echo "profile $profile: decoded by a dynamic reader"
done
