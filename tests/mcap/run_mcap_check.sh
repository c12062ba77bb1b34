#!/usr/bin/env bash
# MCAP recordings checked by the format's own readers, and replayed:
#   1. the main demo's loop (simulator, filter, fault manager) on domain 106, recorded twice at
#      once with `navbus record --all`: as CSV and as one MCAP file;
#   2. Foxglove's libraries (check_mcap.mjs: @mcap/core, @foxglove/omgidl-parser and
#      -serialization) validate the file, its index and summary, decode every message of every
#      topic and compare it with the CSV recording; the channels in Foxglove's schemas that
#      `record --foxglove` adds are valid under Foxglove's published schemas and equal the
#      recorded solutions, decisions, commands and outcomes;
#   3. `navbus replay` of the MCAP file and of the CSV directory, each into a CSV recorder on
#      domain 107: both replays must equal the original recording, bit for bit;
#   4. a ROS 2 named run (--ros2, domain 108) recorded as MCAP with ros2msg schemas, decoded by
#      @foxglove/rosmsg and @foxglove/rosmsg2-serialization.
# The npm packages (tests/mcap/package.json, exact versions) go into BUILD_DIR/mcap-node.
# Usage: run_mcap_check.sh BUILD_DIR SOURCE_DIR
# With KEEP_WORK=1 the scratch directory (printed) is kept, to look at after a failure.
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
bin=$build/bin
MCAP_TEST_NAME=mcap
source "$src/tests/mcap/common.sh"
install_node_readers check_mcap.mjs csv_compare.mjs foxglove_derived.mjs

# Stops the given pids with SIGTERM and checks each exited 0.
stop() {
  local p rc
  for p in "$@"; do kill -TERM "$p" 2> /dev/null || true; done
  for p in "$@"; do
    rc=0
    wait "$p" || rc=$?
    [ $rc -eq 0 ] || fail "process $p exited $rc"
  done
}

# Waits up to 120 s for the given pids to exit by themselves, each with 0.
finished() {
  local p rc deadline=$((SECONDS + 120))
  for p in "$@"; do
    while kill -0 "$p" 2> /dev/null; do
      [ $SECONDS -lt $deadline ] || fail "process $p did not stop by itself"
      sleep 0.2
    done
    rc=0
    wait "$p" || rc=$?
    [ $rc -eq 0 ] || fail "process $p exited $rc"
  done
}

# --- 1. the demo's loop, recorded as CSV and MCAP --------------------------------------------
domain=106
cat > "$work/sim.yaml" << YAML
extends: $src/sim/scenarios/demo_fault_loop.yaml
domain_id: $domain
# The filter, the fault manager and the two recorders read the IMU and the GNSS; the fault
# manager and the recorders the raw IMU.
timing: {min_readers: {imu: 4, raw_imu: 3, gnss: 4, star_tracker: 0}}
YAML
echo "domain_id: $domain" > "$work/fm.yaml"
# Every solution to both recorders, as slow as either is: the default solution writer keeps
# the last 50 (a latest-value stream), which a recorder behind on a loaded machine misses.
# The same for the diagnostics, which the CSV recorder writes as text: with the default
# writer's last 20 epochs it once missed 2 of 120.
printf 'extends: %s\ndomain_id: %s\nsolution_writer_profile: navbus_solution_writer_lossless\ndiagnostics_writer_profile: navbus_diagnostics_writer_lossless\n' \
  "$src/config/filter_demo.yaml" $domain > "$work/filter.yaml"
"$bin/navbus-filter" -c "$work/filter.yaml" > "$work/filter.log" 2>&1 &
filter=$!
"$bin/navbus-fault-manager" -c "$src/config/fault_manager.yaml" -d $domain > "$work/fm.log" 2>&1 &
fm=$!
# The recorders stop by themselves once nothing came for 3 s: each takes everything it was sent,
# however far behind (a SIGTERM would cut a slow one short).
"$bin/navbus" -d $domain record --all -o "$work/csv" --idle 3 > "$work/record_csv.log" 2>&1 &
rec_csv=$!
"$bin/navbus" -d $domain record --all --format mcap --foxglove -o "$work/run.mcap" --idle 3 \
  > "$work/record_mcap.log" 2>&1 &
rec_mcap=$!
pids=($filter $fm $rec_csv $rec_mcap)
# The recorders' readers are volatile: what the filter and the fault manager write before their
# writers matched a recorder is not recorded. The simulator waits for the recorders' sensor
# readers, not for these: wait until each recorder says it matched them.
matched() {  # LOG TOPIC...
  local topic deadline=$((SECONDS + 60))
  for topic in "${@:2}"; do
    until grep -q "$topic: [1-9][0-9]* writer(s) matched" "$1"; do
      [ $SECONDS -lt $deadline ] || fail "$1: no writer of $topic matched within 60 s"
      sleep 0.1
    done
  done
}
for log in "$work/record_csv.log" "$work/record_mcap.log"; do
  matched "$log" navbus/nav/solution navbus/nav/diagnostics navbus/nav/command_outcome \
    navbus/fault/decision navbus/filter/command
done
timeout 120 "$bin/navbus-sensor-sim" -c "$work/sim.yaml" > "$work/sim.log" 2>&1 || fail "simulator"
sleep 1
stop $filter $fm
finished $rec_csv $rec_mcap
pids=()
grep "recorded" "$work/record_mcap.log" | sed 's/^.*\] //'
diff <(grep -o "recorded .*" "$work/record_csv.log") <(grep -o "recorded .*" "$work/record_mcap.log") ||
  echo "(the two recorders took different numbers of some samples: compared by time stamp)"
ls -l "$work/run.mcap" | awk '{print "MCAP file: " $5 " bytes"}'
du -sb "$work/csv" | awk '{print "CSV recording: " $1 " bytes"}'

# --- 2. Foxglove's readers -------------------------------------------------------------------
(cd "$node_dir" && node check_mcap.mjs "$work/run.mcap" "$work/csv" --foxglove) || fail "Foxglove's readers"

# --- 3. replay from MCAP = replay from CSV = the recording -----------------------------------
replay_into() {  # RECORDING OUT_DIR
  local rec_pid
  "$bin/navbus" -d 107 record navbus/imu/increment_block navbus/imu/raw \
    navbus/gnss/observations_block navbus/gnss/fix_block -o "$2" --idle 3 \
    > "$work/replay_record.log" 2>&1 &
  rec_pid=$!
  pids=($rec_pid)
  "$bin/navbus" -d 107 replay "$1" --speed 0 > "$work/replay.log" 2>&1 ||
    fail "navbus replay $1: $(tail -3 "$work/replay.log")"
  wait $rec_pid || fail "the replay's recorder"
  pids=()
}
replay_into "$work/run.mcap" "$work/from_mcap"
replay_into "$work/csv" "$work/from_csv"
for topic in navbus_imu_increment_block navbus_imu_raw navbus_gnss_observations_block \
  navbus_gnss_fix_block; do
  original=$(content "$work/csv/$topic.csv" | md5sum)
  [ "$(content "$work/from_mcap/$topic.csv" | md5sum)" = "$original" ] ||
    fail "$topic replayed from MCAP differs from the recording"
  [ "$(content "$work/from_csv/$topic.csv" | md5sum)" = "$original" ] ||
    fail "$topic replayed from CSV differs from the recording"
  echo "$topic: replayed from MCAP = replayed from CSV = recorded ($(($(wc -l < "$work/csv/$topic.csv") - 1)) rows)"
done

# --- 4. ROS 2 naming: ros2msg schemas ----------------------------------------------------------
domain=108
cat > "$work/sim_ros2.yaml" << YAML
extends: $src/sim/scenarios/seed004_land_vehicle.yaml
domain_id: $domain
ros2_names: true
timing: {duration_s: 10, min_readers: {imu: 2, raw_imu: 2, gnss: 2, star_tracker: 2}}
YAML
"$bin/navbus" --ros2 -d $domain record --all -o "$work/csv_ros2" --idle 3 \
  > "$work/record_csv2.log" 2>&1 &
rec_csv=$!
"$bin/navbus" --ros2 -d $domain record --all --format mcap -o "$work/ros2.mcap" --idle 3 \
  > "$work/record_mcap2.log" 2>&1 &
rec_mcap=$!
pids=($rec_csv $rec_mcap)
timeout 120 "$bin/navbus-sensor-sim" -c "$work/sim_ros2.yaml" > "$work/sim2.log" 2>&1 || fail "simulator (ROS 2)"
finished $rec_csv $rec_mcap
pids=()
(cd "$node_dir" && node check_mcap.mjs "$work/ros2.mcap" "$work/csv_ros2" --ros2) || fail "ROS 2 MCAP"
echo "mcap: ok"
