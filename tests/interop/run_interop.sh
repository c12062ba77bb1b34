#!/usr/bin/env bash
# Cyclone DDS <-> navbus-filter (Fast DDS): the Cyclone peer publishes IMU increments the filter
# must accept, and reads the solutions the filter publishes. Domain 75.
set -euo pipefail
filter_exe=$1 peer_exe=$2 qos_dir=$3
domain=75
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
cat > "$work/filter.yaml" <<YAML
domain_id: $domain
solution_rate_hz: 10
sequencer_max_wait_s: 0.5
initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}
inputs:
  imu: {id: 7, period_s: 0.01}
YAML
"$filter_exe" -c "$work/filter.yaml" > "$work/filter.log" 2>&1 &
filter_pid=$!
export CYCLONEDDS_URI="file://$qos_dir/cyclone_loopback.xml"
status=0
"$peer_exe" $domain 7 300 || status=$?
kill -TERM $filter_pid
wait $filter_pid || true
cat "$work/filter.log"
if ! grep -q "increments integrated 300" "$work/filter.log"; then
  echo "FAIL: navbus-filter did not integrate the 300 increments from Cyclone DDS"
  status=1
fi
exit $status
