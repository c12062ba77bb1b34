#!/usr/bin/env bash
# The main demo's report, after its participants ran (scripts/demo.sh on loopback, or the
# compose demo's `summary` service): the same scenario without DDS (its truth, and the same data
# without the fault manager, to show what the loop saves), then the summary of the logs and the
# recording, and the figures.
# Usage: demo_report.sh BIN_DIR SCRIPTS_DIR SCENARIO FILTER_CONFIG FAULT_MANAGER_CONFIG OUT_DIR
# OUT_DIR holds sensor_sim.log, filter.log, fault_manager.log and record/ (navbus record).
set -euo pipefail
bin=$1 scripts=$2 scenario=$3 filter_cfg=$4 fm_cfg=$5 out=$6
# --start config: the filter starts as its file says, as navbus-filter did on the bus.
"$bin/navbus" offline --scenario "$scenario" --filter "$filter_cfg" --fault-manager "$fm_cfg" \
  --start config -o "$out/offline" > "$out/offline.log" 2>&1
"$bin/navbus" offline --scenario "$scenario" --filter "$filter_cfg" --start config \
  -o "$out/offline_without_fault_manager" > "$out/offline_without_fault_manager.log" 2>&1

echo
echo "================ navbus demo summary ================"
grep -h "summary" "$out/sensor_sim.log" | sed 's/.*summary: /sensor-sim:    /'
grep -h "summary" "$out/filter.log" | sed 's/.*summary: /filter:        /'
grep -h "summary" "$out/fault_manager.log" | sed 's/.*summary: /fault-manager: /'
/usr/bin/python3 "$scripts/demo_summary.py" "$scenario" "$out/record" "$out/offline" \
  "$out/offline_without_fault_manager"
/usr/bin/python3 "$scripts/plot_navbus.py" demo "$scenario" "$out" -o "$out/figures"
echo "logs and CSV files: $out; figures: $out/figures"
