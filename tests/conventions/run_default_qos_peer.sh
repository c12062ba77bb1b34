#!/usr/bin/env bash
# A DDS application with Fast DDS's defaults sees navbus topics when the navbus participants use
# navbus_participant_udp_lan (multicast discovery on the host's interfaces), and does not under
# the default navbus_participant_udp_loopback (unicast discovery on 127.0.0.1 only, which keeps
# the bus off the network); and with --ros2, a reader using ROS 2's topic and type names
# (rt/navbus/imu/increment, navbus::msg::dds_::ImuIncrement_). Domain 63.
set -euo pipefail
bin=$1 peer=$2 scenarios=$3
domain=63
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
cat > "$work/sim.yaml" <<YAML
extends: $scenarios/default.yaml
timing: {min_readers: {imu: 1, raw_imu: 0, gnss: 0, star_tracker: 0}}
YAML
run() {  # profile, expected exit of the peer, [--ros2 topic type]
  local profile=$1 expected=$2
  shift 2
  local sim_args=() peer_args=()
  if [ $# -gt 0 ]; then sim_args=("$1"); peer_args=("$2" "$3"); fi
  "$bin/navbus-sensor-sim" -c "$work/sim.yaml" -d "$domain" --profile "$profile" "${sim_args[@]}" \
    --duration 4 > "$work/sim.log" 2>&1 &
  local sim=$! rc=0
  "$peer" "$domain" 20 3 "${peer_args[@]}" || rc=$?
  kill "$sim" 2>/dev/null || true
  wait "$sim" 2>/dev/null || true
  [[ $rc == "$expected" ]] || { echo "FAIL: profile $profile ${sim_args[*]}: the default-QoS application exited $rc, expected $expected"; cat "$work/sim.log"; exit 1; }
  echo "profile $profile ${sim_args[*]}: default-QoS application exit $rc as expected"
}
run navbus_participant_udp_lan 0
run navbus_participant_udp_loopback 1
# ROS 2 naming (--ros2): a reader with ROS 2's topic and type names receives the samples.
run navbus_participant_udp_lan 0 --ros2 rt/navbus/imu/increment navbus::msg::dds_::ImuIncrement_
