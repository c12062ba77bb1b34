# Shared by run_mcap_check.sh and run_mcap_crash.sh (sourced after `build`, `src` and `bin` are
# set): the scratch directory `work` and its cleanup, fail(), Foxglove's npm readers in
# BUILD_DIR/mcap-node (`node_dir`), and content() of a recorded CSV file.
work=$(mktemp -d "/tmp/navbus-${MCAP_TEST_NAME:-mcap}.XXXXXX")
[ -z "${KEEP_WORK:-}" ] || echo "scratch directory (kept): $work"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -KILL "$p" 2> /dev/null || true; done
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$work"
  rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2> /dev/null || true
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$work"/*.log; do echo "--- $f"; tail -15 "$f"; done
  echo "FAIL: $*"  # again, last: what a truncated log shows
  exit 1
}

# Foxglove's readers (tests/mcap/package.json, exact versions) and the given scripts of
# tests/mcap, in the build directory.
install_node_readers() {
  node_dir=$build/mcap-node
  command -v node > /dev/null && command -v npm > /dev/null || {
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends nodejs npm > /dev/null
  }
  mkdir -p "$node_dir"
  if ! cmp -s "$src/tests/mcap/package-lock.json" "$node_dir/package-lock.json" ||
    [ ! -d "$node_dir/node_modules" ]; then
    cp "$src/tests/mcap/package.json" "$src/tests/mcap/package-lock.json" "$node_dir/"
    (cd "$node_dir" && npm ci --no-audit --no-fund --loglevel=error) || fail "npm ci"
  fi
  local script
  for script in "$@"; do cp "$src/tests/mcap/$script" "$node_dir/"; done
}

# The recorded message columns of a CSV file, without the time stamps of reception.
content() { python3 -c '
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
drop = {i for i, c in enumerate(rows[0]) if c in ("source_timestamp_ns", "reception_timestamp_ns")}
for r in rows:
    print(",".join(c for i, c in enumerate(r) if i not in drop))' "$1"; }
