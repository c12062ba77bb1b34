#!/usr/bin/env bash
# The docker-compose topology without Docker: one Linux network namespace per participant
# (sensor-sim, filter, fault-manager, and an observer running `navbus record`), each with one
# veth into a bridge that lives in its own "switch" namespace, so nothing touches the host's
# interfaces. Participants use the navbus_participant_udp_lan profile (UDP, multicast
# discovery, no shared memory): discovery and data must cross the bridge.
# With `secure CREDENTIALS_DIR`, every participant runs navbus_participant_udp_lan_secure (DDS
# Security) with its own identity from CREDENTIALS_DIR (scripts/make_credentials.sh), on
# another domain and subnet, so both variants can run one after the other.
# Exits 77 (skipped) where network namespaces cannot be created.
set -euo pipefail
bin=$1
mode=${2:-plain}
creds=${3:-}
id=$$
# shellcheck source=namespaces.sh
source "$(dirname "$0")/namespaces.sh"
netns_available

hosts=(sim filter fm obs)
subnet=77
domain=76
profile=navbus_participant_udp_lan
if [ "$mode" = secure ]; then subnet=78; domain=78; profile=navbus_participant_udp_lan_secure; fi
# identity NAME: the credentials option of a participant (none on the plain profile)
identity() { [ "$mode" = secure ] && echo "--identity $creds/$1" || true; }
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  sleep 0.5
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  netns_delete "$id" "${hosts[@]}"
  rm -rf "$work"
}
trap cleanup EXIT

netns_create "$id" "$subnet" "${hosts[@]}"
echo "namespaces: ${hosts[*]} on bridge br0 (10.254.$subnet.0/24), profile $profile"

common=(--domain $domain --profile $profile)
cat > "$work/filter.yaml" <<YAML
initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}
inputs:
  imu: {id: 1, period_s: 0.01}
  gnss_observations: {id: 1, period_s: 1.0}
  gnss_fix: {id: 1, period_s: 1.0}
  star_tracker: {id: 1, period_s: 0.2}
YAML
cat > "$work/sim.yaml" <<YAML
timing: {start: now, duration_s: 60, pacing: realtime, wait_for_readers_s: 25,
         min_readers: {imu: 2, raw_imu: 1, gnss: 2, star_tracker: 2}}
YAML

ip netns exec "nbfilter$id" "$bin/navbus-filter" -c "$work/filter.yaml" "${common[@]}" $(identity filter) > "$work/filter.log" 2>&1 &
pids+=($!)
ip netns exec "nbfm$id" "$bin/navbus-fault-manager" "${common[@]}" $(identity fault-manager) > "$work/fm.log" 2>&1 &
pids+=($!)
ip netns exec "nbobs$id" "$bin/navbus" "${common[@]}" $(identity tool) record navbus/nav/solution navbus/fault/decision \
  -o "$work/rec" --duration 90 > "$work/rec.log" 2>&1 &
rec_pid=$!
pids+=($rec_pid)
sleep 1
# start_sim: starts the simulator and waits until it publishes (its readers matched). Fast DDS
# 2.9 gives up a secure handshake after a fixed number of requests; under the sanitizers on a
# busy 2-core machine one between the simulator and the filter was once lost that way (the
# filter never matched the IMU writer in 30 s). A simulator whose readers did not all match is
# stopped and started again (a new participant, a new handshake), at most three times.
start_sim() {
  ip netns exec "nbsim$id" "$bin/navbus-sensor-sim" -c "$work/sim.yaml" "${common[@]}" $(identity simulator) > "$work/sim.log" 2>&1 &
  sim_pid=$!
  for _ in $(seq 1 400); do
    grep -q "publishing" "$work/sim.log" 2>/dev/null && break
    sleep 0.1
  done
}
for attempt in 1 2 3; do
  start_sim
  grep -q "readers not all matched" "$work/sim.log" || break
  echo "attempt $attempt: the simulator's readers did not all match; starting it again"
  cat "$work/sim.log"
  [ "$attempt" = 3 ] && break
  kill -KILL $sim_pid 2>/dev/null || true
  wait $sim_pid 2>/dev/null || true
done
grep -q "publishing" "$work/sim.log" || echo "the simulator did not start publishing within 40 s"
# A clean end of data is announced (no loss); a crash is not: kill the simulator after 4 s of
# data so that the watchdog's decision has to cross the namespaces.
sleep 4
kill -KILL $sim_pid 2>/dev/null || true
wait $sim_pid 2>/dev/null || true
sleep 3
kill -TERM $rec_pid
wait $rec_pid || true

solutions=$(($(wc -l < "$work/rec/navbus_nav_solution.csv") - 1))
lost=$(grep -c "STREAM_LOST,IMU_STREAM," "$work/rec/navbus_fault_decision.csv" || true)
echo "observer namespace recorded $solutions solutions and $lost IMU stream-lost decisions"
cat "$work/sim.log"
status=0
# At least 3 s of data at 10 Hz before the kill, published by the filter in another namespace.
if [ "$solutions" -lt 30 ]; then echo "FAIL: expected at least 30 solutions across namespaces"; status=1; fi
if [ "$lost" -lt 1 ]; then echo "FAIL: no IMU stream-lost decision crossed the namespaces"; status=1; fi
if [ $status -ne 0 ]; then cat "$work/filter.log" "$work/fm.log" "$work/rec.log"; fi
exit $status
