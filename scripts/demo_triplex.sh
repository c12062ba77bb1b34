#!/usr/bin/env bash
# The redundant-IMU demo (issue "redundant sensors"): three navigation-grade IMUs on seed 000's
# aircraft (sim/scenarios/seed000_triplex_gyro_ramp.yaml); from 700 s the x gyro of IMU 1, the
# filter's own unit, ramps slowly. navbus-sensor-sim publishes all three units,
# navbus-fault-manager runs its parity test on them (config/fault_manager_triplex.yaml) and
# navbus-filter runs one lane per unit (config/filter_triplex.yaml); a recorder keeps the
# published solution, every lane's and the decisions. The same data then runs offline twice:
# the same three processes' pipelines (the bus run must equal it), and one filter on IMU 1 alone
# without the parity test, which absorbs the ramp. Prints the decision, the switch with its
# reset deltas and the errors; draws build/demo_triplex/figures/triplex.png.
# Installs what is missing and builds first, as scripts/demo.sh does.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
mkdir -p build
bash scripts/build.sh > build/demo-build.log 2>&1 || { tail -50 build/demo-build.log; exit 1; }
bin=build/bin
domain=${NAVBUS_DEMO_DOMAIN:-0}
out=build/demo_triplex
scenario=sim/scenarios/seed000_triplex_gyro_ramp.yaml
lanes_cfg=config/filter_triplex.yaml
single_cfg=config/filter_seed000_tc.yaml
fm_cfg=config/fault_manager_triplex.yaml
duration_s=900
rm -rf "$out" && mkdir -p "$out"
# The scenario, cut to the demo's length, on the demo's domain.
cat > "$out/scenario.yaml" <<YAML
extends: $(pwd)/$scenario
timing: {duration_s: $duration_s}
YAML
# Offline first, without DDS: the lanes with the parity test (what the bus run must equal), and
# one filter on IMU 1 alone without the parity test.
"$bin/navbus" offline --scenario "$out/scenario.yaml" --filter "$lanes_cfg" --fault-manager "$fm_cfg" \
  --start config -o "$out/offline" > "$out/offline.log" 2>&1
"$bin/navbus" offline --scenario "$out/scenario.yaml" --filter "$single_cfg" --start config \
  -o "$out/offline_single_lane" > "$out/offline_single_lane.log" 2>&1
# The recorder gets every solution (lossless writer), as in the main demo.
cat > "$out/filter.yaml" <<YAML
extends: $(pwd)/$lanes_cfg
solution_writer_profile: navbus_solution_writer_lossless
YAML
pids=()
trap 'kill -TERM "${pids[@]}" 2>/dev/null || true' EXIT
"$bin/navbus-filter" -c "$out/filter.yaml" -d "$domain" > "$out/filter.log" 2>&1 &
filter=$!
"$bin/navbus-fault-manager" -c "$fm_cfg" -d "$domain" > "$out/fault_manager.log" 2>&1 &
fm=$!
"$bin/navbus" -d "$domain" record navbus/nav/solution navbus/nav/lane_solution \
  navbus/fault/decision navbus/filter/command -o "$out/record" > "$out/record.log" 2>&1 &
rec=$!
pids=($filter $fm $rec)
echo "demo (triplex): filter (three lanes), fault manager (parity test) and recorder on domain $domain;"
echo "      the simulator publishes $duration_s s of three IMUs as fast as they take it (IMU 1's x gyro ramps from 700 s)"
"$bin/navbus-sensor-sim" -c "$out/scenario.yaml" -d "$domain" > "$out/sensor_sim.log" 2>&1
# The lanes finish after the simulator: each waits for the fault manager's judgement of the
# data. Wait until the recorder has every solution the offline run published (at most 60 s).
solutions="$out/record/navbus_nav_solution.csv"
expected=$(( $(wc -l < "$out/offline/solution.csv") - 1 ))
for _ in $(seq 1 120); do
  [ $(( $(wc -l < "$solutions" 2>/dev/null || echo 1) - 1 )) -ge "$expected" ] && break
  sleep 0.5
done
kill -TERM $filter $fm
wait $filter $fm 2>/dev/null || true
sleep 0.5
kill -TERM $rec
wait $rec 2>/dev/null || true
trap - EXIT

echo
echo "================ navbus triplex demo summary ================"
grep -h "lanes: switched" "$out/filter.log" | sed 's/.*\] //' || true
/usr/bin/python3 scripts/triplex_summary.py "$scenario" "$out/offline" "$out/offline_single_lane" \
  "$out/record"
/usr/bin/python3 scripts/plot_navbus.py triplex "$scenario" "$out/offline" \
  "$out/offline_single_lane" -o "$out/figures"
echo "logs and CSV files: $out; figures: $out/figures"
