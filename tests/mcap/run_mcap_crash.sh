#!/usr/bin/env bash
# A recorder killed with SIGKILL loses at most --flush-s of the recording:
#   1. the demo's loop (simulator in real-time pacing, filter, fault manager) on domain 111,
#      recorded as CSV to the end and as MCAP with --flush-s 1 by a recorder killed -9 mid-run;
#   2. `navbus recover` closes the cut file; Foxglove's indexed reader (check_mcap.mjs: summary,
#      chunk and message indexes, every message decoded and equal to the CSV recording) reads the
#      recovered file, and check_crash.mjs finds in it every message the CSV recorder received
#      more than --flush-s (plus the recorder's 50 ms loop) before the kill;
#   3. `navbus replay` of the cut file and of the recovered file, each into a CSV recorder on
#      domain 112, replay the same samples, bit for bit;
#   4. `navbus offline --recording` of the two files gives the same solutions, bit for bit.
# Usage: run_mcap_crash.sh BUILD_DIR SOURCE_DIR (npm packages as run_mcap_check.sh installs them)
# With KEEP_WORK=1 the scratch directory (printed) is kept.
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
bin=$build/bin
MCAP_TEST_NAME=mcap-crash
source "$src/tests/mcap/common.sh"
install_node_readers check_mcap.mjs csv_compare.mjs check_crash.mjs foxglove_derived.mjs
flush_s=1
kill_after_s=12.5  # half a flush interval after the recorders flush (they start together)

# --- 1. the demo's loop in real time, the MCAP recorder killed ------------------------------
domain=111
cat > "$work/sim.yaml" << YAML
extends: $src/sim/scenarios/demo_fault_loop.yaml
domain_id: $domain
timing: {duration_s: 25, pacing: realtime, min_readers: {imu: 4, raw_imu: 3, gnss: 4, star_tracker: 0}}
YAML
printf 'extends: %s\ndomain_id: %s\nsolution_writer_profile: navbus_solution_writer_lossless\ndiagnostics_writer_profile: navbus_diagnostics_writer_lossless\n' \
  "$src/config/filter_demo.yaml" $domain > "$work/filter.yaml"
"$bin/navbus-filter" -c "$work/filter.yaml" > "$work/filter.log" 2>&1 &
filter=$!
"$bin/navbus-fault-manager" -c "$src/config/fault_manager.yaml" -d $domain > "$work/fm.log" 2>&1 &
fm=$!
"$bin/navbus" -d $domain record --all -o "$work/csv" --idle 3 > "$work/record_csv.log" 2>&1 &
rec_csv=$!
"$bin/navbus" -d $domain record --all --format mcap -o "$work/run.mcap" --flush-s $flush_s \
  > "$work/record_mcap.log" 2>&1 &
rec_mcap=$!
pids=($filter $fm $rec_csv $rec_mcap)
for log in "$work/record_csv.log" "$work/record_mcap.log"; do
  deadline=$((SECONDS + 60))
  until grep -q "navbus/nav/solution: [1-9][0-9]* writer(s) matched" "$log" &&
    grep -q "navbus/fault/decision: [1-9][0-9]* writer(s) matched" "$log"; do
    [ $SECONDS -lt $deadline ] || fail "$log: the filter's writers did not match within 60 s"
    sleep 0.1
  done
done
timeout 120 "$bin/navbus-sensor-sim" -c "$work/sim.yaml" > "$work/sim.log" 2>&1 &
sim=$!
pids+=($sim)
# Kill kill_after_s seconds after the first solution reached the CSV recorder's file (which it
# flushes every second too).
deadline=$((SECONDS + 60))
until [ "$(wc -l < "$work/csv/navbus_nav_solution.csv" 2> /dev/null || echo 0)" -gt 1 ]; do
  [ $SECONDS -lt $deadline ] || fail "no solution within 60 s"
  sleep 0.1
done
sleep $kill_after_s
kill_ns=$(date +%s%N)
kill -KILL $rec_mcap
wait $rec_mcap 2> /dev/null || true
wait $sim || fail "simulator"
sleep 1
for p in $filter $fm; do kill -TERM $p; done
for p in $filter $fm; do wait $p || fail "process $p exited $?"; done
wait $rec_csv || fail "CSV recorder"
pids=()
ls -l "$work/run.mcap" | awk '{print "MCAP file at the kill: " $5 " bytes"}'

# --- 2. recovered, and read by Foxglove's indexed reader -------------------------------------
"$bin/navbus" recover "$work/run.mcap" -o "$work/recovered.mcap" | tee "$work/recover.log" ||
  fail "navbus recover"
grep -q "cut short" "$work/recover.log" || fail "navbus recover did not see the cut"
(cd "$node_dir" && node check_mcap.mjs "$work/recovered.mcap" "$work/csv") ||
  fail "Foxglove's readers on the recovered file"
(cd "$node_dir" && node check_crash.mjs "$work/recovered.mcap" "$work/csv" "$kill_ns" \
  "$flush_s") || fail "messages older than --flush-s lost"

# --- 3. the cut file replays as the recovered one ---------------------------------------------
replay_into() {  # RECORDING OUT_DIR
  local rec_pid
  "$bin/navbus" -d 112 record navbus/imu/increment navbus/imu/raw navbus/gnss/observations \
    navbus/gnss/fix -o "$2" --idle 3 > "$work/replay_record.log" 2>&1 &
  rec_pid=$!
  pids=($rec_pid)
  "$bin/navbus" -d 112 replay "$1" --speed 0 > "$work/replay.log" 2>&1 ||
    fail "navbus replay $1: $(tail -3 "$work/replay.log")"
  wait $rec_pid || fail "the replay's recorder"
  pids=()
}
replay_into "$work/run.mcap" "$work/from_cut"
grep -q "cut short" "$work/replay.log" || fail "navbus replay did not say the file was cut"
grep -o "cut short.*" "$work/replay.log" | head -1
replay_into "$work/recovered.mcap" "$work/from_recovered"
for topic in navbus_imu_increment navbus_imu_raw navbus_gnss_observations navbus_gnss_fix; do
  [ "$(content "$work/from_cut/$topic.csv" | md5sum)" = \
    "$(content "$work/from_recovered/$topic.csv" | md5sum)" ] ||
    fail "$topic replayed from the cut file differs from the recovered file's replay"
  echo "$topic: replayed from the cut file = from the recovered file ($(($(wc -l < "$work/from_cut/$topic.csv") - 1)) rows)"
done

# --- 4. navbus offline reads the cut file as the recovered one --------------------------------
for f in run recovered; do
  "$bin/navbus" offline --recording "$work/$f.mcap" --filter "$src/config/filter_demo.yaml" \
    -o "$work/offline_$f" > "$work/offline_$f.log" 2>&1 || fail "navbus offline --recording $f.mcap"
done
grep -q "cut short" "$work/offline_run.log" || fail "navbus offline did not say the file was cut"
cmp -s "$work/offline_run/solution.csv" "$work/offline_recovered/solution.csv" ||
  fail "navbus offline: the cut file's solutions differ from the recovered file's"
echo "navbus offline: the cut file and the recovered file give the same $(($(wc -l < "$work/offline_run/solution.csv") - 1)) solutions"
echo "mcap crash: ok"
