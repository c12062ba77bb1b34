#!/usr/bin/env bash
# CPU starvation: the three participants in real time (default scenario: IMU 100 Hz, raw IMU
# 2400 Hz, GNSS 1 Hz, star tracker 5 Hz) beside BURNERS CPU-bound processes on the machine's
# cores. Passes when no stream is declared lost (the data never stops), every increment is
# integrated with no inertial gap, and no input is rejected (late or otherwise).
# Usage: run_cpu_load.sh BIN_DIR SOURCE_DIR [BURNERS] [DURATION_S]   (domain 94)
set -euo pipefail
bin=$1; src=$2; burners=${3:-2}; duration=${4:-20}
domain=94
out=$(mktemp -d)
pids=()
cleanup() { kill "${pids[@]}" 2>/dev/null || true; rm -rf "$out"; }
trap cleanup EXIT
for _ in $(seq "$burners"); do (while :; do :; done) & pids+=($!); done
"$bin/navbus-filter" -c "$src/config/filter.yaml" -d $domain > "$out/filter.log" 2>&1 &
filter=$!
"$bin/navbus-fault-manager" -c "$src/config/fault_manager.yaml" -d $domain > "$out/fm.log" 2>&1 &
fm=$!
pids+=($filter $fm)
"$bin/navbus-sensor-sim" -c "$src/sim/scenarios/default.yaml" -d $domain --duration "$duration" \
  > "$out/sim.log" 2>&1
sleep 1
kill -TERM $filter $fm
wait $filter $fm || true
expected=$((duration * 100))
echo "$burners CPU-bound processes beside the participants, $duration s of real-time data:"
grep -h "summary" "$out/filter.log" "$out/fm.log" | sed 's/.*summary: /  /' | cut -c1-220
status=0
check() {  # file pattern description
  if ! grep -q "$2" "$1"; then echo "FAIL: $3"; status=1; fi
}
check "$out/filter.log" "increments integrated $expected refused by the engine 0" "not every increment integrated"
check "$out/filter.log" "inertial gaps 0" "inertial gaps"
check "$out/filter.log" "navbus/imu/increment: received $expected, accepted $expected, rejected 0" "IMU inputs rejected or lost"
check "$out/fm.log" "stream lost 0" "a stream was declared lost while it flowed"
if grep -h "rejected [1-9]" "$out/filter.log"; then echo "FAIL: inputs rejected"; status=1; fi
grep -h "deadline events not confirmed by the silence [0-9]*" -o "$out/fm.log" || true
if [ $status -ne 0 ]; then cat "$out/filter.log" "$out/fm.log" "$out/sim.log"; fi
exit $status
