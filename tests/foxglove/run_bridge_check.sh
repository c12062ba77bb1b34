#!/usr/bin/env bash
# `navbus foxglove` beside the demo's loop (domain 113), checked by Foxglove's own client:
#   1. the simulator (real-time pacing, IMU at 200 Hz), the filter with its low-latency output,
#      the fault manager, a CSV recorder and the bridge on a free port of 127.0.0.1;
#   2. check_bridge.mjs (@foxglove/ws-protocol) subscribes to every channel as it is advertised,
#      parses every schema, decodes every message, compares the middle message of each channel
#      with the CSV recording and prints the bridge hop on the low-latency solution; the
#      LocationFix track and the Log lines equal the recorded solutions and the operator's
#      commands and the filter's answers (one applied, one refused) sent mid-run; the
#      repository's Foxglove layout names only advertised topics and plots only numbers;
#   3. hostile_clients.mjs, at the same time: malformed JSON, an unknown op, a subscription to an
#      unknown channel, a binary message, an oversized message, a client that stops reading and
#      one that disconnects mid-frame; each gets its error and the checked client sees nothing
#      of it;
#   4. the bridge's own summary and its health reports (navbus-foxglove) in the CSV recording.
# Usage: run_bridge_check.sh BUILD_DIR SOURCE_DIR. KEEP_WORK=1 keeps the scratch directory.
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
bin=$build/bin
MCAP_TEST_NAME=foxglove
source "$src/tests/mcap/common.sh"
install_node_readers csv_compare.mjs foxglove_derived.mjs
cp "$src/tests/foxglove/check_bridge.mjs" "$src/tests/foxglove/hostile_clients.mjs" \
  "$src/tests/foxglove/layout_check.mjs" "$node_dir/"

domain=113
cat > "$work/sim.yaml" << YAML
extends: $src/sim/scenarios/demo_fault_loop.yaml
domain_id: $domain
timing: {duration_s: 15, pacing: realtime, imu_rate_hz: 200,
         min_readers: {imu: 3, raw_imu: 3, gnss: 3, star_tracker: 0}}
YAML
printf 'extends: %s\ndomain_id: %s\nlow_latency_output: {enabled: true}\nsolution_writer_profile: navbus_solution_writer_lossless\ndiagnostics_writer_profile: navbus_diagnostics_writer_lossless\n' \
  "$src/config/filter_demo.yaml" $domain > "$work/filter.yaml"
"$bin/navbus-filter" -c "$work/filter.yaml" > "$work/filter.log" 2>&1 &
filter=$!
"$bin/navbus-fault-manager" -c "$src/config/fault_manager.yaml" -d $domain > "$work/fm.log" 2>&1 &
fm=$!
"$bin/navbus" -d $domain record --all -o "$work/csv" --idle 3 > "$work/record_csv.log" 2>&1 &
rec=$!
"$bin/navbus" -d $domain foxglove --port 0 > "$work/bridge.log" 2>&1 &
bridge=$!
pids=($filter $fm $rec $bridge)
deadline=$((SECONDS + 60))
until port=$(grep -o "ws://127.0.0.1:[0-9]*" "$work/bridge.log" | head -1 | cut -d: -f3) &&
  [ -n "$port" ]; do
  [ $SECONDS -lt $deadline ] || fail "the bridge did not listen within 60 s"
  kill -0 $bridge 2> /dev/null || fail "the bridge exited"
  sleep 0.1
done
until grep -q "navbus/nav/solution: [1-9][0-9]* writer(s) matched" "$work/record_csv.log" &&
  grep -q "navbus/nav/solution_low_latency: advertised" "$work/bridge.log"; do
  [ $SECONDS -lt $deadline ] || fail "the filter's writers did not match within 60 s"
  sleep 0.1
done
(cd "$node_dir" && node check_bridge.mjs "ws://127.0.0.1:$port" "$work/csv" 24 \
  "$src/config/foxglove/navbus_layout.json") \
  > "$work/check.log" 2>&1 &
check=$!
(cd "$node_dir" && node hostile_clients.mjs "ws://127.0.0.1:$port") > "$work/hostile.log" 2>&1 &
hostile=$!
pids+=($check $hostile)
until grep -q "^connected" "$work/check.log"; do
  [ $SECONDS -lt $deadline ] || fail "the checking client did not connect"
  sleep 0.1
done
"$bin/navbus-sensor-sim" -c "$work/sim.yaml" > "$work/sim.log" 2>&1 &
sim=$!
pids+=($sim)
# An operator's commands in the middle of the run (the scenario's faults come after 15 s): one
# the filter applies and one it refuses (an issuer it does not obey), for the Log channel.
until grep -q "publishing" "$work/sim.log"; do
  [ $SECONDS -lt $deadline ] || fail "the simulator did not start publishing"
  sleep 0.1
done
sleep 5
# Three readers of the commands: the filter, the bridge and the CSV recorder.
"$bin/navbus" -d $domain command EXCLUDE_SATELLITE --sv 5 --issuer operator --min-readers 3 \
  > "$work/command1.log" 2>&1 || fail "command: $(cat "$work/command1.log")"
grep -q "vehicle 1: APPLIED" "$work/command1.log" || fail "not applied: $(cat "$work/command1.log")"
! "$bin/navbus" -d $domain command READMIT_SATELLITE --sv 5 --issuer stranger --min-readers 3 \
  > "$work/command2.log" 2>&1 || fail "the stranger's command exited 0"
grep -q "vehicle 1: REFUSED (unauthorized)" "$work/command2.log" ||
  fail "the stranger's command was not refused: $(cat "$work/command2.log")"
timeout 120 tail --pid=$sim -f /dev/null || fail "the simulator did not end"
wait $sim || fail "simulator"
sleep 1
for p in $filter $fm; do kill -TERM $p; done
for p in $filter $fm; do wait $p || fail "process $p exited $?"; done
wait $hostile || fail "hostile clients: $(tail -5 "$work/hostile.log")"
cat "$work/hostile.log"
# The bridge's own health keeps the CSV recorder busy: the bridge stops once the checking
# client has stopped listening, then the recorder goes idle and stops.
until grep -q "^listening done" "$work/check.log"; do
  kill -0 $check 2> /dev/null || fail "the checking client: $(tail -20 "$work/check.log")"
  sleep 0.2
done
kill -TERM $bridge
wait $bridge || fail "the bridge exited $?"
wait $rec || fail "CSV recorder"
touch "$work/csv.done"
wait $check || fail "the checking client: $(tail -20 "$work/check.log")"
cat "$work/check.log"
pids=()
summary=$(grep -o "foxglove bridge: .*" "$work/bridge.log") || fail "no summary from the bridge"
echo "$summary"
dropped=$(echo "$summary" | grep -o "dropped for clients behind [0-9]*" | grep -o "[0-9]*$")
[ "$dropped" -gt 0 ] || fail "the stalled reader lost no frame: its backlog went elsewhere"
grep -q "navbus-foxglove" "$work/csv/navbus_health.csv" ||
  fail "no health report of navbus-foxglove in the recording"
echo "health: $(grep -c "navbus-foxglove" "$work/csv/navbus_health.csv") rows of navbus-foxglove in navbus_health.csv"
echo "foxglove bridge: ok"
