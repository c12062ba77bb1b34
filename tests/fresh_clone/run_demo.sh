#!/usr/bin/env bash
# The README's demo command from a fresh clone of the committed tree (HEAD), as a new user
# runs it: a clean directory with no build/, ../shared beside it when the checkout has one.
# Fails if the demo fails or its summary lacks what it promises. Uncommitted changes are not
# part of a clone: the script says so when the working tree is dirty.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
if [ -n "$(git -C "$src" status --porcelain --untracked-files=no)" ]; then
  echo "fresh-clone demo: note: uncommitted changes in $src are not tested (only HEAD is cloned)"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git clone -q "$src" "$work/main"
[ -d "$src/../shared" ] && cp -r "$src/../shared" "$work/shared"
cd "$work/main"
# A domain of its own, so that a concurrent run on the default domain 0 cannot interfere.
if ! NAVBUS_DEMO_DOMAIN=${NAVBUS_DEMO_DOMAIN:-90} bash scripts/demo.sh > "$work/demo.out" 2>&1; then
  echo "fresh-clone demo: FAILED"; tail -60 "$work/demo.out"; exit 1
fi
cat "$work/demo.out"
# On a failed check, what the fault manager decided and why (the clone is removed on exit).
diagnose() {
  echo "fresh-clone demo: fault manager warnings:"
  grep -E "warn|LOST|RESTORED" build/demo/fault_manager.log | tail -20 || true
}

# The loop: both faults decided and acted on, the error after each inside the envelope, no
# loss reported at the end of the data, and the figures written.
for expected in "navbus demo summary" "sensor-sim:" "filter:" "fault-manager:" \
    "glr FAULT_DETECTED SATELLITE sv 13" "EXCLUDE_SATELLITE sv 13" \
    "dither-fft FAULT_DETECTED ACCELEROMETER axis x" "FAIL_SENSOR_AXIS ACCELEROMETER axis x" \
    "mode AIDED_AXIS_FAILED" "end of data: 0 stream-lost"; do
  grep -q "$expected" "$work/demo.out" || {
    echo "fresh-clone demo: summary lacks '$expected'"; diagnose; exit 1; }
done
if grep "^  after " "$work/demo.out" | grep -qv "100 % of solutions inside it"; then
  echo "fresh-clone demo: an error after a fault leaves the 3-sigma envelope"; diagnose; exit 1
fi
for fig in errors with_without_fault_manager glr; do
  size=$(stat -c %s "build/demo/figures/$fig.png" 2>/dev/null || echo 0)
  [ "$size" -gt 20000 ] || { echo "fresh-clone demo: figure $fig.png missing or trivial ($size bytes)"; exit 1; }
done
echo "fresh-clone demo: passed"
