#!/usr/bin/env bash
# Each paper's scenario through navbus-sensor-sim, to files and over the bus (a `navbus record`
# observer), for a few seconds of data; the row and sample counts must match the rates.
# Domains 80-83.
set -euo pipefail
bin=$1 scenarios=$2
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
seconds=3
status=0
domain=80
check() {  # name expected actual
  if [ "$2" -eq "$3" ]; then echo "  ok   $1: $3"; else echo "  FAIL $1: expected $2, got $3"; status=1; fi
}
rows() { echo $(($(wc -l < "$1") - 1)); }
for scenario in seed000_aircraft:100:1:0 seed001_leo:200:10:5 seed003_laser_ins:100:0:0 seed004_land_vehicle:50:1:0; do
  IFS=: read -r name imu_hz gnss_hz st_hz <<< "$scenario"
  file="$scenarios/$name.yaml"
  echo "$name ($imu_hz Hz IMU, $gnss_hz Hz GNSS, $st_hz Hz star tracker), $seconds s"
  # To files.
  "$bin/navbus-sensor-sim" --scenario "$file" --files "$work/$name" --duration $seconds > "$work/$name.files.log" 2>&1 \
    || { cat "$work/$name.files.log"; exit 1; }
  check "imu.csv rows" $((imu_hz * seconds)) "$(rows "$work/$name/imu.csv")"
  check "truth.csv rows" $((imu_hz * seconds)) "$(rows "$work/$name/truth.csv")"
  check "gnss_fix.csv rows" $((gnss_hz * seconds)) "$(rows "$work/$name/gnss_fix.csv")"
  check "star_tracker.csv rows" $((st_hz * seconds)) "$(rows "$work/$name/star_tracker.csv")"
  # Over the bus, fast pacing, recorded by a separate participant (the only reader here).
  # Fast pacing sends every stream in blocks (navbus/imu/increment_block, navbus/gnss/fix_block,
  # ...): a CSV row per element.
  cat > "$work/$name.bus.yaml" <<YAML
extends: $file
timing: {min_readers: {imu: 1, raw_imu: 1, gnss: 1, star_tracker: 1}}
YAML
  topics=(navbus/imu/increment_block navbus/imu/raw)
  [ "$gnss_hz" -gt 0 ] && topics+=(navbus/gnss/observations_block navbus/gnss/fix_block)
  [ "$st_hz" -gt 0 ] && topics+=(navbus/startracker/attitude_block)
  # The recorder stops itself once nothing has come for 3 s (--idle): killing it as soon as the
  # simulator exits lost what was still queued for it (seed 003's 2400 Hz raw stream under the
  # sanitizers: 10 increments of 300 recorded); 60 s at most.
  "$bin/navbus" -d $domain record "${topics[@]}" --idle 3 --duration 60 -o "$work/$name.bus" > "$work/$name.rec.log" 2>&1 &
  rec=$!
  "$bin/navbus-sensor-sim" --scenario "$work/$name.bus.yaml" -d $domain --duration $seconds --pacing fast > "$work/$name.bus.log" 2>&1 \
    || { cat "$work/$name.bus.log"; exit 1; }
  wait $rec || true
  check "bus imu increments" $((imu_hz * seconds)) "$(rows "$work/$name.bus/navbus_imu_increment_block.csv")"
  if [ "$gnss_hz" -gt 0 ]; then check "bus gnss fixes" $((gnss_hz * seconds)) "$(rows "$work/$name.bus/navbus_gnss_fix_block.csv")"; fi
  if [ "$st_hz" -gt 0 ]; then check "bus star-tracker attitudes" $((st_hz * seconds)) "$(rows "$work/$name.bus/navbus_startracker_attitude_block.csv")"; fi
  domain=$((domain + 1))
done
exit $status
