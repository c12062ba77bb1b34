#!/usr/bin/env bash
# The figure commands (scripts/plot_navbus.py) on small data: each writes a non-trivial PNG.
# usage: run.sh NAVBUS_EXE SENSOR_SIM_EXE
set -euo pipefail
navbus=$1
sim=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scenario=$src/sim/scenarios/demo_fault_loop.yaml
"$navbus" offline --scenario "$scenario" --filter "$src/config/filter_demo.yaml" \
  --fault-manager "$src/config/fault_manager.yaml" --start config --duration 45 -o "$work/with" > "$work/with.log" 2>&1
"$navbus" offline --scenario "$scenario" --filter "$src/config/filter_demo.yaml" --duration 45 \
  --start config -o "$work/without" > "$work/without.log" 2>&1
"$sim" -c "$src/sim/scenarios/seed003_laser_ins.yaml" --files "$work/raw" --duration 41 \
  > "$work/raw.log" 2>&1
"$navbus" montecarlo --scenario "$src/sim/scenarios/seed000_pseudorange_ramp_12p5.yaml" \
  --filter "$src/config/filter_seed000_tc.yaml" --fault-manager "$src/config/fault_manager.yaml" \
  --runs 4 --start config --duration 700 --from 100 --csv "$work/mc" > "$work/mc.log" 2>&1
# The CSV files carry what the figures show: the demo's ramp detected by the GLR, and one row
# per Monte Carlo run with its detection.
grep -q ',1$' "$work/with/glr.csv" || { echo "glr.csv: no detected epoch"; exit 1; }
detected=$(awk -F, 'NR > 1 && $4 == 1' "$work/mc/faults.csv" | wc -l)
echo "montecarlo faults.csv: $detected of 4 runs detected"
[ "$detected" -eq 4 ] || { cat "$work/mc.log"; exit 1; }
"$navbus" benchmark real-car "$src/config/datasets/drive_0708.yaml" \
  --filter "$src/config/filter_drive_0708.yaml" \
  --outages "$src/config/datasets/drive_0708_outages.txt" --smooth -o "$work/real" \
  > "$work/real.log" 2>&1 || { cat "$work/real.log"; exit 1; }
"$navbus" benchmark real-data "$src/config/datasets/walk_0827.yaml" \
  --filter "$src/config/filter_walk_0827_tc.yaml" -o "$work/walk" \
  > "$work/walk.log" 2>&1 || { cat "$work/walk.log"; exit 1; }
py=/usr/bin/python3
$py "$src/scripts/plot_navbus.py" realcar "$work/real" --name drive_0708 -o "$work/fig"
$py "$src/scripts/plot_navbus.py" realcar "$work/walk" --name walk_0827 -o "$work/fig"
$py "$src/scripts/plot_navbus.py" errors "$work/with" -o "$work/fig"
$py "$src/scripts/plot_navbus.py" compare "$work/with" "$work/without" -o "$work/fig"
$py "$src/scripts/plot_navbus.py" spectrum "$work/raw/imu_raw.csv" --before 40 --after 40.2 \
  --axis x -o "$work/fig"
$py "$src/scripts/plot_navbus.py" glr "$work/with" -o "$work/fig" --scenario "$scenario"
$py "$src/scripts/plot_navbus.py" montecarlo "$work/mc" -o "$work/fig"
# The walk's pseudorange errors against its RTK reference (docs/real_data.md section 6): 4
# satellites, sigma 5.47 m, the figure behind ekf.pseudorange_error_sigma_m.
$py "$src/scripts/pseudorange_errors.py" "$work/walk/recording" | tee "$work/pr.log"
[ "$(grep -c '^ *[0-9]\+ \+349 ' "$work/pr.log")" -eq 4 ] || { echo "pseudorange_errors.py: not 4 satellites"; exit 1; }
grep -q "RMS over satellites: sigma 5.4[0-9] m" "$work/pr.log" ||
  { echo "pseudorange_errors.py: sigma not 5.4x m"; exit 1; }
for f in errors with_without_fault_manager spectrum_x glr nees detection_delay drive_0708 walk_0827; do
  size=$(stat -c %s "$work/fig/$f.png" 2>/dev/null || echo 0)
  echo "figure $f.png: $size bytes"
  [ "$size" -gt 20000 ] || { echo "figure $f.png missing or trivial"; exit 1; }
done
echo "figures: passed"
