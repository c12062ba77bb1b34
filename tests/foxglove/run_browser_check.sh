#!/usr/bin/env bash
# `navbus foxglove` from a real browser (domain 114): the bridge beside a filter (whose writers
# make the bridge advertise the solution, diagnostics, outcome and health channels and the
# LocationFix and Log channels derived from them), and check_browser.mjs drives Debian's
# Chromium to open it with the foxglove.websocket.v1 subprotocol and list the topics.
# Exits 77 (ctest: skipped) where Chromium is not installed or cannot start.
# Usage: run_browser_check.sh BUILD_DIR SOURCE_DIR. KEEP_WORK=1 keeps the scratch directory.
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
bin=$build/bin
MCAP_TEST_NAME=browser
source "$src/tests/mcap/common.sh"
chromium=${CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ]; then
  echo "SKIP: no $chromium (Debian's chromium: scripts/install-deps.sh installs it)"
  exit 77
fi
install_node_readers
cp "$src/tests/foxglove/check_browser.mjs" "$src/tests/foxglove/browser_page.html" "$node_dir/"

domain=114
# No fault manager here: the filter does not wait for one (filter_demo.yaml's judged_from_start).
printf 'extends: %s\ndomain_id: %s\nfault_monitor: {judged_from_start: false}\n' \
  "$src/config/filter_demo.yaml" $domain > "$work/filter.yaml"
"$bin/navbus-filter" -c "$work/filter.yaml" > "$work/filter.log" 2>&1 &
pids+=($!)
"$bin/navbus" -d $domain foxglove --port 0 > "$work/bridge.log" 2>&1 &
bridge=$!
pids+=($bridge)
deadline=$((SECONDS + 60))
until grep -q "navbus/foxglove/location_fix: advertised" "$work/bridge.log"; do
  [ $SECONDS -lt $deadline ] || fail "the bridge did not advertise the filter's solution within 60 s"
  kill -0 $bridge 2> /dev/null || fail "the bridge exited"
  sleep 0.1
done
port=$(grep -o "ws://127.0.0.1:[0-9]*" "$work/bridge.log" | head -1 | cut -d: -f3)
status=0
(cd "$node_dir" && CHROMIUM=$chromium node check_browser.mjs "ws://127.0.0.1:$port" \
  "$node_dir/browser_page.html" navbus/nav/solution navbus/foxglove/location_fix navbus/health) \
  > "$work/browser.log" 2>&1 || status=$?
cat "$work/browser.log"
[ $status -ne 77 ] || exit 77
[ $status -eq 0 ] || fail "the browser check (exit $status)"
kill -TERM $bridge
wait $bridge || fail "the bridge exited $?"
summary=$(grep -o "foxglove bridge: .*" "$work/bridge.log") || fail "no summary from the bridge"
echo "$summary"
echo "$summary" | grep -q "handshakes refused [1-9]" ||
  fail "the bridge did not count the browser's handshake without the subprotocol"
echo "foxglove browser: ok"
