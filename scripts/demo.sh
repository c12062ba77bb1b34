#!/usr/bin/env bash
# Installs what is missing, builds (reusing an existing build), and runs the main demo: the
# fault-tolerant loop. navbus-sensor-sim, navbus-filter (tightly coupled) and
# navbus-fault-manager run as separate processes on loopback with a `navbus record` observer;
# the scenario (sim/scenarios/demo_fault_loop.yaml) injects a pseudorange ramp and a stuck
# accelerometer. The summary shows, per fault, the error before it, the decision, the
# reconfiguration and the error after it; the figures go next to the CSV files.
# NAVBUS_SECURE=1 runs the four participants under DDS Security (secure loopback profile, the
# test credentials the build makes in build/security).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
mkdir -p build   # a fresh clone has no build/ yet: the build log goes there
bash scripts/build.sh > build/demo-build.log 2>&1 || { tail -50 build/demo-build.log; exit 1; }
bin=build/bin
domain=${NAVBUS_DEMO_DOMAIN:-0}
out=build/demo
scenario=sim/scenarios/demo_fault_loop.yaml
filter_cfg=config/filter_demo.yaml
fm_cfg=config/fault_manager.yaml
rm -rf "$out" && mkdir -p "$out"
# bus_args IDENTITY: the participant profile and, when secure, the credentials of IDENTITY.
bus_args() { :; }
if [ "${NAVBUS_SECURE:-0}" = 1 ]; then
  bus_args() { echo "--profile navbus_participant_udp_loopback_secure --identity build/security/$1"; }
fi
pids=()
trap 'kill -TERM "${pids[@]}" 2>/dev/null || true' EXIT

"$bin/navbus-filter" -c "$filter_cfg" -d "$domain" $(bus_args filter) > "$out/filter.log" 2>&1 &
filter=$!
"$bin/navbus-fault-manager" -c "$fm_cfg" -d "$domain" $(bus_args fault-manager) > "$out/fault_manager.log" 2>&1 &
fm=$!
"$bin/navbus" -d "$domain" $(bus_args tool) record navbus/nav/solution navbus/fault/decision navbus/filter/command \
  -o "$out/record" > "$out/record.log" 2>&1 &
rec=$!
pids=($filter $fm $rec)
echo "demo: filter, fault manager and recorder started on domain $domain$([ "${NAVBUS_SECURE:-0}" = 1 ] && echo ' under DDS Security'); the simulator publishes"
echo "      120 s of data as fast as they take it (pseudorange ramp at 30 s, stuck accelerometer at 65 s)"
"$bin/navbus-sensor-sim" -c "$scenario" -d "$domain" $(bus_args simulator) > "$out/sensor_sim.log" 2>&1
sleep 1   # the filter releases its last inputs
kill -TERM $filter $fm
wait $filter $fm 2>/dev/null || true
sleep 0.5
kill -TERM $rec
wait $rec 2>/dev/null || true
trap - EXIT

bash scripts/demo_report.sh "$bin" scripts "$scenario" "$filter_cfg" "$fm_cfg" "$out"
