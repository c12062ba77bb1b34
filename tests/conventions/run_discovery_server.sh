#!/usr/bin/env bash
# The inspection tools under a discovery server: a server on a port of our own (not the default
# 11811, which other tests use), the simulator as a discovery client, and `navbus topics` and
# `navbus echo` as clients of the same server given by --discovery-server. A plain CLIENT only
# learns the endpoints matching its own, so `topics` saw nothing but itself; the tools take
# the SUPER_CLIENT role and see every endpoint. Domain 64, server port 11832.
set -euo pipefail
bin=$1 scenarios=$2
domain=64 port=11832
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; cat "$work"/*.log >&2; exit 1; }
client=(-d "$domain" --profile navbus_participant_discovery_client --discovery-server "127.0.0.1:$port")

# The server binary itself: `fastdds discovery` is a launcher whose server survived the kill
# of the launcher and stayed after the test.
fast-discovery-server -i 0 -l 127.0.0.1 -p "$port" > "$work/server.log" 2>&1 &
cat > "$work/sim.yaml" <<YAML
extends: $scenarios/default.yaml
timing: {min_readers: {imu: 1, raw_imu: 0, gnss: 0, star_tracker: 0}}
YAML
"$bin/navbus-sensor-sim" -c "$work/sim.yaml" "${client[@]}" --duration 6 > "$work/sim.log" 2>&1 &

"$bin/navbus" "${client[@]}" topics --wait 2 > "$work/topics.out" 2> "$work/topics.log"
cat "$work/topics.out"
grep -Eq "^navbus/imu/increment +navbus::ImuIncrement +1 " "$work/topics.out" ||
  fail "topics under the discovery server does not show the simulator's IMU writer"
"$bin/navbus" "${client[@]}" echo navbus/imu/increment -n 3 > "$work/echo.out" 2> "$work/echo.log" ||
  fail "echo under the discovery server received fewer than 3 samples"
[[ $(grep -c "^--- navbus/imu/increment #" "$work/echo.out") == 3 ]] || fail "echo printed $(cat "$work/echo.out")"
echo "echo under the discovery server: 3 samples"

set +e
"$bin/navbus" -d "$domain" --discovery-server 127.0.0.1 topics --wait 0.1 > /dev/null 2> "$work/refused.log"
rc=$?
set -e
[[ $rc == 3 ]] && grep -q "needs a discovery-client profile" "$work/refused.log" ||
  fail "a server address with a non-client profile: exit $rc"
echo "discovery server: ok"
