#!/usr/bin/env bash
# One participant of the compose demo, by role: the command each service runs, installed as
# bin/navbus-demo-participant. The compose file and the network-namespace test both run this
# script with docker/demo.env's variables, so they run the same commands.
#   filter, fault-manager  stop by themselves once the simulator ended its IMU stream
#   simulator              the main demo's scenario (pseudorange ramp, stuck accelerometer),
#                          fast pacing; it also waits for the recorder before the first sample
#   recorder               solutions, decisions, commands and the IMU blocks into $NAVBUS_OUT,
#                          stops when nothing came for 5 s
#   summary                the same report as scripts/demo.sh, once the others have finished
#   health NAME            healthcheck: NAME's own health reports say RUNNING or DEGRADED
# Each role's log goes to $NAVBUS_OUT/<log> as well as to stdout.
set -euo pipefail
role=${1:?usage: participant.sh filter|fault-manager|simulator|recorder|summary|health NAME}
bin=$(cd "$(dirname "$(readlink -f "$0")")" && pwd)
share=$(cd "$bin/../share/navbus" && pwd)
out=${NAVBUS_OUT:?} domain=${NAVBUS_DOMAIN:?} profile=${NAVBUS_PROFILE:?}
scenario=$share/scenarios/demo_fault_loop.yaml
filter_cfg=$share/config/filter_demo.yaml
fm_cfg=$share/config/fault_manager.yaml
common=(-d "$domain" --profile "$profile")
# Under DDS Security (docker/docker-compose.secure.yml): this service's credentials directory.
if [ -n "${NAVBUS_IDENTITY:-}" ]; then common+=(--identity "$NAVBUS_IDENTITY"); fi
[ "$role" = health ] || mkdir -p "$out"
log() { exec > >(tee "$out/$1") 2>&1; }

case $role in
  filter)
    log filter.log
    exec "$bin/navbus-filter" -c "$filter_cfg" "${common[@]}" --exit-when-ended ;;
  fault-manager)
    log fault_manager.log
    exec "$bin/navbus-fault-manager" -c "$fm_cfg" "${common[@]}" --exit-when-ended ;;
  simulator)
    log sensor_sim.log
    # The recorder reads the IMU blocks too: a third IMU reader to wait for, so that it has
    # matched before the first sample and records the run from its start.
    cat > "$out/simulator.yaml" <<YAML
extends: $scenario
timing: {min_readers: {imu: 3, raw_imu: 1, gnss: 2, star_tracker: 0}}
YAML
    exec "$bin/navbus-sensor-sim" -c "$out/simulator.yaml" "${common[@]}" ;;
  recorder)
    log record.log
    exec "$bin/navbus" "${common[@]}" record navbus/nav/solution navbus/fault/decision \
      navbus/filter/command navbus/imu/increment_block -o "$out/record" --idle 5 ;;
  health)
    # A healthcheck: the service's participant reports RUNNING or DEGRADED on navbus/health.
    exec "$bin/navbus" "${common[@]}" health "${2:?participant name}" --timeout 5 ;;
  summary)
    exec bash "$share/scripts/demo_report.sh" "$bin" "$share/scripts" "$scenario" "$filter_cfg" \
      "$fm_cfg" "$out" ;;
  *)
    echo "unknown role '$role' (filter, fault-manager, simulator, recorder, summary)" >&2
    exit 2 ;;
esac
