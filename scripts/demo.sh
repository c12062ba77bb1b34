#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default demo: navbus-filter,
# navbus-fault-manager and navbus-sensor-sim as separate processes on loopback, with a
# `navbus record` observer. The simulator publishes 20 s of data and stops; the fault manager
# declares its streams lost; everything then stops and a summary is printed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
mkdir -p build   # a fresh clone has no build/ yet: the build log goes there
bash scripts/build.sh > build/demo-build.log 2>&1 || { tail -50 build/demo-build.log; exit 1; }
bin=build/bin
domain=${NAVBUS_DEMO_DOMAIN:-0}
out=build/demo
rm -rf "$out" && mkdir -p "$out"
pids=()
trap 'kill -TERM "${pids[@]}" 2>/dev/null || true' EXIT

"$bin/navbus-filter" -c config/filter.yaml -d "$domain" > "$out/filter.log" 2>&1 &
pids+=($!)
"$bin/navbus-fault-manager" -c config/fault_manager.yaml -d "$domain" > "$out/fault_manager.log" 2>&1 &
pids+=($!)
"$bin/navbus" -d "$domain" record navbus/nav/solution navbus/fault/decision navbus/health -o "$out/record" \
  > "$out/record.log" 2>&1 &
rec=$!
pids+=($rec)
echo "demo: filter, fault manager and recorder started on domain $domain; simulator publishing 20 s of data"
"$bin/navbus-sensor-sim" -c sim/scenarios/default.yaml -d "$domain" 2>&1 | tee "$out/sensor_sim.log" | grep -E "summary|warn|error" || true
sleep 3   # the watchdogs see the streams stop
kill -TERM "${pids[@]}"
wait "${pids[@]}" 2>/dev/null || true
trap - EXIT

echo
echo "================ navbus demo summary ================"
grep -h "summary" "$out/sensor_sim.log" | sed 's/.*summary: /sensor-sim:    /'
grep -h -A7 "summary" "$out/filter.log" | sed 's/.*summary: /filter:        /'
grep -h -A6 "summary" "$out/fault_manager.log" | sed 's/.*summary: /fault-manager: /'
solutions=$(($(wc -l < "$out/record/navbus_nav_solution.csv") - 1))
decisions=$(($(wc -l < "$out/record/navbus_fault_decision.csv") - 1))
echo "recorder:      $solutions solutions and $decisions fault decisions recorded in $out/record"
# CSV columns are read by their header names (see the README's CSV section).
awk -F, 'NR==1 {for (i = 1; i <= NF; ++i) c[$i] = i; next}
  NR==2 {lat0=$c["latitude_rad"]; lon0=$c["longitude_rad"]; h0=$c["height_m"]}
  $c["mode"]=="INERTIAL_ONLY" {lat=$c["latitude_rad"]; lon=$c["longitude_rad"]; h=$c["height_m"]; t=1}
  END { if (t) printf("last inertial solution: drift north %.3f m, east %.3f m, up %.3f m from the first solution\n",
        (lat-lat0)*6.3567e6, (lon-lon0)*6.3567e6*cos(lat0), h-h0) }' "$out/record/navbus_nav_solution.csv"
awk -F, 'NR==1 {for (i = 1; i <= NF; ++i) c[$i] = i; next}
  {print "decision:      " $c["detector"] " " $c["event"] " " $c["source"]}' \
  "$out/record/navbus_fault_decision.csv" | sort | uniq -c
echo "logs and CSV files: $out"
