#!/usr/bin/env bash
# The bridge never slows the bus: the main demo's loop (simulator, filter, fault manager) in
# fast pacing, as fast as its reliable readers take the data (domain 115), six times,
# alternating: without the bridge (A1, A2, A3) and with `navbus foxglove` (its default
# niceness) and 10 Foxglove clients (@foxglove/ws-protocol, one Node process) subscribed to
# every channel (B1, B2, B3). The clients stand for viewers on other machines: here they share
# the 2 cores, so they run at niceness 19, and what is measured is the bridge's own cost.
# Each run's bus solutions (a recorder of navbus/nav/solution) must equal `navbus offline` of
# the same loop bit for bit; the simulator's throughput (data seconds per wall second, its own
# summary) is printed per run, and the median with the bridge as a ratio to the median without,
# beside the spread of the runs without it; the bridge's per-client account (frames sent,
# dropped for being behind) and the samples its best-effort readers missed are printed and each
# client must have its line.
# Usage: run_bridge_load.sh BUILD_DIR SOURCE_DIR [DURATION_S] (default 60: the pseudorange
# ramp and its exclusion; over the whole 120 s, the stuck accelerometer's command lands one
# solution later over the bus than offline in some runs, with or without the bridge). KEEP_WORK=1 keeps the scratch.
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
duration=${3:-60}
bin=$build/bin
MCAP_TEST_NAME=foxglove-load
source "$src/tests/mcap/common.sh"
install_node_readers
cp "$src/tests/foxglove/load_clients.mjs" "$node_dir/"
clients=10
domain=115

# The simulator starts once its minimum of readers matched; it counts every reader, the
# bridge's best-effort ones too, so with the bridge the minimum is one more per stream (else
# the simulator may start before the filter matched, and the filter misses the first data).
for readers in "2 1 2" "3 2 3"; do
  set -- $readers
  printf 'extends: %s\ndomain_id: %s\ntiming: {duration_s: %s, pacing: fast,\n  min_readers: {imu: %s, raw_imu: %s, gnss: %s, star_tracker: 0}}\n' \
    "$src/sim/scenarios/demo_fault_loop.yaml" $domain "$duration" $1 $2 $3 \
    > "$work/sim_${1}.yaml"
done
cp "$work/sim_2.yaml" "$work/sim.yaml"
# As tests/integration/test_offline_equals_bus.cpp: every solution kept for the recorder, and
# the sequencer's and the fault monitor's wall-clock bounds wide enough for a loaded machine.
printf '%s\n' "extends: $src/config/filter_demo.yaml" "domain_id: $domain" \
  "solution_writer_profile: navbus_solution_writer_lossless" "sequencer_max_wait_s: 30" \
  "fault_monitor: {participant: navbus-fault-manager, timeout_s: 30}" > "$work/filter.yaml"
printf 'extends: %s\ndomain_id: %s\n' "$src/config/fault_manager.yaml" $domain > "$work/fm.yaml"

"$bin/navbus" offline --scenario "$work/sim.yaml" --filter "$work/filter.yaml" \
  --fault-manager "$work/fm.yaml" --start config -o "$work/offline" > "$work/offline.log" 2>&1 ||
  fail "navbus offline"

# One run of the loop; $1 names it, $2 = "bridge" adds the bridge and its clients.
run_loop() {
  local name=$1 with=${2:-} dir=$work/$1
  mkdir -p "$dir"
  "$bin/navbus-filter" -c "$work/filter.yaml" > "$dir/filter.log" 2>&1 &
  local filter=$!
  "$bin/navbus-fault-manager" -c "$work/fm.yaml" > "$dir/fm.log" 2>&1 &
  local fm=$!
  "$bin/navbus" -d $domain record navbus/nav/solution -o "$dir/csv" --idle 5 \
    > "$dir/record.log" 2>&1 &
  local rec=$!
  pids+=($filter $fm $rec)
  local bridge="" load=""
  if [ "$with" = bridge ]; then
    "$bin/navbus" -d $domain foxglove --port 0 > "$dir/bridge.log" 2>&1 &
    bridge=$!
    pids+=($bridge)
    local deadline=$((SECONDS + 60)) port=""
    until port=$(grep -o "ws://127.0.0.1:[0-9]*" "$dir/bridge.log" | head -1 | cut -d: -f3) &&
      [ -n "$port" ]; do
      [ $SECONDS -lt $deadline ] || fail "$name: the bridge did not listen"
      sleep 0.1
    done
    (cd "$node_dir" && nice -n 19 node load_clients.mjs "ws://127.0.0.1:$port" $clients \
      "$dir/stop") \
      > "$dir/clients.log" 2>&1 &
    load=$!
    pids+=($load)
    until grep -q "^connected" "$dir/clients.log"; do
      [ $SECONDS -lt $deadline ] || fail "$name: the clients did not connect"
      sleep 0.1
    done
  fi
  local deadline=$((SECONDS + 60))
  until grep -q "navbus/nav/solution: [1-9][0-9]* writer(s) matched" "$dir/record.log"; do
    [ $SECONDS -lt $deadline ] || fail "$name: the recorder did not match the filter"
    sleep 0.1
  done
  local sim_cfg=$work/sim_2.yaml
  [ "$with" != bridge ] || sim_cfg=$work/sim_3.yaml
  timeout 600 "$bin/navbus-sensor-sim" -c "$sim_cfg" > "$dir/sim.log" 2>&1 ||
    fail "$name: simulator"
  wait $rec || fail "$name: recorder"
  for p in $filter $fm; do kill -TERM $p; done
  for p in $filter $fm; do wait $p || fail "$name: process $p exited $?"; done
  if [ -n "$bridge" ]; then
    kill -TERM $bridge
    wait $bridge || fail "$name: the bridge exited $?"
    touch "$dir/stop"
    wait $load || fail "$name: the clients: $(tail -12 "$dir/clients.log")"
  fi
  pids=()
  rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2> /dev/null || true
  grep -o "throughput: .*" "$dir/sim.log" | head -1 > "$dir/throughput" ||
    fail "$name: no throughput line from the simulator"
}

for i in 1 2 3; do
  run_loop A$i
  run_loop B$i bridge
done

/usr/bin/python3 - "$work" $clients << 'PY'
import csv, re, sys
work, clients = sys.argv[1], int(sys.argv[2])

def rows(path, keep):
    with open(path, newline="") as f:
        r = csv.DictReader(f)
        cols = [c for c in r.fieldnames if not c.endswith("timestamp_ns")]
        return cols, [[row[c] for c in cols] for row in r if keep(row)]

cols, expected = rows(f"{work}/offline/solution.csv", lambda row: True)
failed = False
speed = {}
for name in ["A1", "B1", "A2", "B2", "A3", "B3"]:
    got_cols, got = rows(f"{work}/{name}/csv/navbus_nav_solution.csv",
                         lambda row: row["mode"] != "INERTIAL_LOST")
    differing = sum(a != b for a, b in zip(got, expected)) + abs(len(got) - len(expected))
    line = open(f"{work}/{name}/throughput").read()
    m = re.search(r"([0-9.]+) s of data in ([0-9.]+) s", line)
    speed[name] = float(m.group(1)) / float(m.group(2))
    ok = got_cols == cols and differing == 0
    failed |= not ok
    print(f"run {name}{' (bridge, %d clients)' % clients if name[0] == 'B' else ''}: "
          f"{len(got)} bus solutions, {len(expected)} offline, "
          f"{'bit-identical' if ok else f'{differing} differ'}; simulator {speed[name]:.1f}x real time")
without = sorted(v for k, v in speed.items() if k[0] == "A")
with_bridge = sorted(v for k, v in speed.items() if k[0] == "B")
median_a, median_b = without[1], with_bridge[1]
print(f"throughput, median of 3: without the bridge {median_a:.1f}x, with it {median_b:.1f}x "
      f"real time: ratio {median_b / median_a:.3f}; the runs without it spread "
      f"{100 * (without[2] - without[0]) / median_a:.1f} % (max - min over median)")
sys.exit(1 if failed else 0)
PY
[ $? -eq 0 ] || fail "bus = offline does not hold"
for i in 1 2 3; do
  [ "$(grep -c "client [0-9]* (.*frames sent" "$work/B$i/bridge.log")" -eq $clients ] ||
    fail "B$i: the bridge did not account for each of its $clients clients"
done
grep -o "client [0-9]* (.*" "$work/B3/bridge.log"
grep -o "foxglove bridge: .*" "$work/B3/bridge.log"
grep "^client" "$work/B3/clients.log"
echo "foxglove load: ok"
