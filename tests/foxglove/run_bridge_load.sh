#!/usr/bin/env bash
# The bridge never slows the bus: the main demo's loop (simulator, filter, fault manager) in
# fast pacing, as fast as its reliable readers take the data (domain 115), three times:
#   A. alone; B. with `navbus foxglove` and 10 Foxglove clients (@foxglove/ws-protocol, one Node
#   process) subscribed to every channel; C. alone again.
# Each run's bus solutions (a recorder of navbus/nav/solution) must equal `navbus offline` of
# the same loop bit for bit; the simulator's throughput (data seconds per wall second, its own
# summary) with the bridge is printed as a ratio to the mean of the two runs without it, beside
# their own spread; the bridge's per-client account (frames sent, dropped for being behind) and
# the samples its best-effort readers missed are printed and each client must have its line.
# Usage: run_bridge_load.sh BUILD_DIR SOURCE_DIR [DURATION_S]. KEEP_WORK=1 keeps the scratch.
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

printf 'extends: %s\ndomain_id: %s\ntiming: {duration_s: %s, pacing: fast}\n' \
  "$src/sim/scenarios/demo_fault_loop.yaml" $domain "$duration" > "$work/sim.yaml"
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
    (cd "$node_dir" && node load_clients.mjs "ws://127.0.0.1:$port" $clients "$dir/stop") \
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
  timeout 600 "$bin/navbus-sensor-sim" -c "$work/sim.yaml" > "$dir/sim.log" 2>&1 ||
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

run_loop A
run_loop B bridge
run_loop C

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
for name in "ABC":
    got_cols, got = rows(f"{work}/{name}/csv/navbus_nav_solution.csv",
                         lambda row: row["mode"] != "INERTIAL_LOST")
    differing = sum(a != b for a, b in zip(got, expected)) + abs(len(got) - len(expected))
    line = open(f"{work}/{name}/throughput").read()
    m = re.search(r"([0-9.]+) s of data in ([0-9.]+) s", line)
    speed[name] = float(m.group(1)) / float(m.group(2))
    ok = got_cols == cols and differing == 0
    failed |= not ok
    print(f"run {name}{' (bridge, %d clients)' % clients if name == 'B' else ''}: "
          f"{len(got)} bus solutions, {len(expected)} offline, "
          f"{'bit-identical' if ok else f'{differing} differ'}; simulator {speed[name]:.1f}x real time")
base = (speed["A"] + speed["C"]) / 2
spread = abs(speed["A"] - speed["C"]) / base
print(f"throughput with the bridge / without: {speed['B'] / base:.3f} "
      f"(the two runs without it differ by {100 * spread:.1f} %)")
sys.exit(1 if failed else 0)
PY
[ $? -eq 0 ] || fail "bus = offline does not hold"
grep -o "client [0-9]* (.*" "$work/B/bridge.log"
[ "$(grep -c "client [0-9]* (.*frames sent" "$work/B/bridge.log")" -eq $clients ] ||
  fail "the bridge did not account for each of its $clients clients"
grep -o "foxglove bridge: .*" "$work/B/bridge.log"
grep "^client" "$work/B/clients.log"
echo "foxglove load: ok"
