#!/usr/bin/env bash
# The real-time option (a `realtime:` block in any participant's configuration; domain 118):
#   1. navbus-filter with {policy: fifo, priority: 10, cpus: [the last core], lock_memory: true}:
#      every thread of the process (the Fast DDS threads it created included) runs SCHED_FIFO on
#      that core at priority 10, the main (processing) thread at the DDS threads' priority (not
#      above them: docs/bus.md), but the housekeeping thread, back at SCHED_OTHER on that core;
#      with locked memory (VmLck > 0), as the kernel reports in /proc;
#   2. the fault manager and the simulator take the same block and report the same grant;
#   3. refusals are configuration errors (exit 2) naming the key and the system's reason:
#      without CAP_SYS_NICE, with a locked-memory limit of 0 and no CAP_IPC_LOCK, a core this
#      machine does not have, a priority out of range.
# Usage: run_realtime_check.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
bin=$build/bin
work=$(mktemp -d /tmp/navbus-realtime.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -KILL "$p" 2> /dev/null || true; done
  rm -rf "$work"
  rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2> /dev/null || true
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$work"/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -8 "$f"; }; done
  exit 1
}
domain=118
core=$(($(nproc) - 1))
block="realtime: {policy: fifo, priority: 10, cpus: [$core], lock_memory: true}"
config() {  # config NAME BASE [BLOCK [MORE]]
  printf '%s\n' "extends: $2" "domain_id: $domain" "${3:-$block}" "${4:-}" > "$work/$1.yaml"
}
config filter "$src/config/filter_demo.yaml"
config fm "$src/config/fault_manager.yaml"
config sim "$src/sim/scenarios/demo_fault_loop.yaml" "$block" \
  "timing: {duration_s: 1, min_readers: {imu: 0, raw_imu: 0, gnss: 0, star_tracker: 0}}"

# --- 1. what the kernel granted the filter's threads ----------------------------------------
"$bin/navbus-filter" -c "$work/filter.yaml" > "$work/filter.log" 2>&1 &
filter=$!
pids+=($filter)
deadline=$((SECONDS + 30))
until grep -q "real-time: granted" "$work/filter.log"; do
  [ $SECONDS -lt $deadline ] || fail "no grant reported by the filter"
  kill -0 $filter 2> /dev/null || fail "the filter exited"
  sleep 0.1
done
sleep 1  # the DDS threads of the participant and its entities are all there by now
grep -o "real-time: .*" "$work/filter.log"
threads=0 housekeeping=0
for task in /proc/$filter/task/*; do
  tid=${task##*/}
  # /proc/TID/stat: the fields after "(comm)"; rt_priority is field 40, policy field 41.
  read -r -a f <<< "$(sed 's/^.*) //' "$task/stat")"
  priority=${f[37]} policy=${f[38]}
  cpus=$(awk '/^Cpus_allowed_list/ {print $2}' "$task/status")
  name=$(cat "$task/comm")
  echo "thread $tid ($name): policy $policy priority $priority cpus $cpus"
  [ "$cpus" = "$core" ] || fail "thread $tid ($name) on cpus $cpus, not $core"
  if [ "$name" = navbus-housekp ]; then
    # The shared-memory reclaim's thread goes back to the normal class: it must not preempt.
    [ "$policy" = 0 ] || fail "housekeeping thread $tid has policy $policy, not SCHED_OTHER (0)"
    housekeeping=$((housekeeping + 1))
    continue
  fi
  [ "$policy" = 1 ] || fail "thread $tid ($name) has policy $policy, not SCHED_FIFO (1)"
  [ "$priority" = 10 ] || fail "thread $tid ($name) at priority $priority, not 10"
  threads=$((threads + 1))
done
locked=$(awk '/^VmLck/ {print $2}' /proc/$filter/status)
echo "$threads threads SCHED_FIFO on core $core; VmLck $locked kB"
[ "$threads" -ge 5 ] || fail "only $threads threads: the DDS threads are not there"
[ "$housekeeping" = 1 ] || fail "$housekeeping housekeeping threads, not 1"
if [ -n "${ASAN_OPTIONS:-}" ]; then
  # AddressSanitizer ignores mlockall: the filter must say so, not claim a lock.
  grep -q "memory not locked" "$work/filter.log" && grep -q "ignores mlockall" "$work/filter.log" ||
    fail "under AddressSanitizer the filter claimed locked memory"
  echo "AddressSanitizer build: memory not locked, and the filter says so"
else
  [ "$locked" -gt 0 ] || fail "no memory locked"
fi
kill -TERM $filter
wait $filter || fail "the filter exited $?"

# --- 2. the same block in the other participants' files --------------------------------------
"$bin/navbus-fault-manager" -c "$work/fm.yaml" > "$work/fm.log" 2>&1 &
fm=$!
pids+=($fm)
deadline=$((SECONDS + 30))
until grep -q "real-time: granted" "$work/fm.log"; do
  [ $SECONDS -lt $deadline ] || fail "no grant reported by the fault manager"
  sleep 0.1
done
kill -TERM $fm
wait $fm || fail "the fault manager exited $?"
grep -o "real-time: .*" "$work/fm.log"
timeout 20 "$bin/navbus-sensor-sim" -c "$work/sim.yaml" > "$work/sim.log" 2>&1 || true
grep -q "real-time: granted policy fifo priority 10, cpus \[$core\], memory" "$work/sim.log" ||
  fail "no grant reported by the simulator"
grep -o "real-time: .*" "$work/sim.log"

# --- 3. refusals --------------------------------------------------------------------------
refused() {  # refused NAME EXPECTED-TEXT COMMAND...
  local name=$1 text=$2
  shift 2
  local status=0
  timeout 30 "$@" > "$work/$name.log" 2>&1 || status=$?
  [ $status -eq 2 ] || fail "$name: exit $status, not 2 (configuration error)"
  grep -qF "$text" "$work/$name.log" || fail "$name: no '$text' in $(cat "$work/$name.log")"
  echo "$name: $(grep -o "configuration realtime.*" "$work/$name.log")"
}
config nice "$src/config/filter_demo.yaml" "realtime: {policy: fifo, priority: 10}"
refused no_cap_sys_nice "realtime.policy = fifo (priority 10) refused: Operation not permitted" \
  setpriv --inh-caps=-sys_nice --bounding-set=-sys_nice "$bin/navbus-filter" -c "$work/nice.yaml"
config lock "$src/config/filter_demo.yaml" "realtime: {lock_memory: true}"
if [ -n "${ASAN_OPTIONS:-}" ]; then
  echo "memlock_limit: not produced (AddressSanitizer ignores mlockall: nothing to refuse)"
else
  refused memlock_limit "realtime.lock_memory = true refused" \
    prlimit --memlock=0:0 setpriv --inh-caps=-ipc_lock --bounding-set=-ipc_lock \
    "$bin/navbus-filter" -c "$work/lock.yaml"
fi
config cpus "$src/config/filter_demo.yaml" "realtime: {cpus: [1000]}"
refused missing_core "realtime.cpus = [1000] refused: Invalid argument" \
  "$bin/navbus-filter" -c "$work/cpus.yaml"
config range "$src/config/filter_demo.yaml" "realtime: {policy: rr, priority: 0}"
refused priority_range "realtime.priority = 0 is outside 1..99 for policy rr" \
  "$bin/navbus-filter" -c "$work/range.yaml"
echo "realtime: ok"
