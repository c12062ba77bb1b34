#!/usr/bin/env bash
# `navbus latency table` end to end, small (domains 120-125): every row of the table (raw,
# navbus, navbus with the real-time option; idle and beside one CPU-bound process) received all
# its samples, the ratios and the four targets are printed, the real-time rows' core is named,
# and a child that cannot start or a core the machine does not have is an error naming it. The
# figures themselves are the benchmark's (docs/results.md), not asserted.
# Needs CAP_SYS_NICE for the real-time rows (root here, as the realtime test).
set -euo pipefail
build=$1
src=$2
bin=$build/bin
cd "$src"
out=$(mktemp)
trap 'rm -f "$out"' EXIT
"$bin/navbus" -d 120 latency table --samples 300 --warmup 30 --hogs 1 > "$out" 2>&1 || {
  cat "$out"; echo "FAIL: latency table exited $?"; exit 1; }
cat "$out"
rows=$(grep -cE "^(idle|loaded) +(raw Fast DDS round trip|navbus|navbus, real-time option) .* 300 of 300" "$out")
[ "$rows" = 6 ] || { echo "FAIL: expected 6 rows with 300 of 300 samples, found $rows"; exit 1; }
[ "$(grep -c "VmHWM" "$out")" = 4 ] || { echo "FAIL: expected navbus-filter's VmHWM on its 4 rows"; exit 1; }
[ "$(grep -cE "\(target <= [0-9.]+x\): (met|NOT met)" "$out")" = 4 ] || { echo "FAIL: expected 4 target verdicts"; exit 1; }
# The real-time rows on one core (the last by default), named in the header.
last=$(($(nproc) - 1))
grep -q "memory locked, cpus \[$last\] (navbus-filter and its IMU source)" "$out" ||
  { echo "FAIL: the header does not name the real-time rows' core $last"; exit 1; }
# A core this machine does not have: an error naming it, exit 1, no table.
if "$bin/navbus" -d 120 latency table --cpus 4096 > "$out" 2>&1; then
  echo "FAIL: --cpus 4096 was accepted"; exit 1
fi
grep -q -- "--cpus 4096: this machine has cores 0..$last" "$out" ||
  { cat "$out"; echo "FAIL: the error does not name the core"; exit 1; }
# A configuration that does not exist: an error naming it, exit 1, no table.
if "$bin/navbus" -d 120 latency table --filter-config /nonexistent/filter.yaml > "$out" 2>&1; then
  echo "FAIL: a missing --filter-config was accepted"; exit 1
fi
grep -q "filter-config '/nonexistent/filter.yaml': no such file" "$out" ||
  { cat "$out"; echo "FAIL: the error does not name the file"; exit 1; }
echo "latency table: ok"
