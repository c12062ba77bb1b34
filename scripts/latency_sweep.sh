#!/usr/bin/env bash
# Raw Fast DDS latency and saturation throughput of navbus's IMU message, per participant
# profile and per stream QoS, in one table (`navbus latency ping/pong` and `flood/sink`, two
# processes each). Profiles: UDP loopback, shared memory, a discovery server (started here:
# fast-discovery-server, Fast DDS's `fastdds discovery`, on 127.0.0.1:11811) and UDP loopback under DDS Security (the build's
# test credentials). QoS: the sensor profiles (reliable, KEEP_ALL) and the best-effort probe
# profiles (KEEP_LAST 100). The LAN profile needs a second host: tests/netns runs it.
#   bash scripts/latency_sweep.sh [SAMPLES]      (default 2000 pings at 200 Hz per case)
# Environment: SWEEP_DIR (raw outputs; default a new temporary directory), SWEEP_DOMAIN
# (first DDS domain, default 170), NAVBUS_BIN (default build/bin), NAVBUS_CREDENTIALS
# (default build/security).
set -euo pipefail
cd "$(dirname "$0")/.."
samples=${1:-2000}
bin=${NAVBUS_BIN:-build/bin}
creds=${NAVBUS_CREDENTIALS:-build/security}
dir=${SWEEP_DIR:-$(mktemp -d)}
domain=${SWEEP_DOMAIN:-170}
[ -x "$bin/navbus" ] || bash scripts/build.sh
mkdir -p "$dir"

server=
cleanup() {
  if [ -n "$server" ]; then kill "$server" 2>/dev/null || true; fi
  rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2>/dev/null || true
}
trap cleanup EXIT
# The server binary itself (`fastdds discovery` is a wrapper that leaves it running when killed).
fast-discovery-server -i 0 -l 127.0.0.1 -p 11811 >"$dir/discovery_server.txt" 2>&1 &
server=$!
sleep 1
if ! kill -0 "$server" 2>/dev/null; then
  echo "latency_sweep: the discovery server did not start on 127.0.0.1:11811 (port in use?):" >&2
  cat "$dir/discovery_server.txt" >&2
  exit 1
fi

profiles=(navbus_participant_udp_loopback navbus_participant_shm
          navbus_participant_discovery_client navbus_participant_udp_loopback_secure)
run_case() {  # profile, qos tag, then the stream profile options
  local profile=$1 qos=$2 tag="$1.$2"
  shift 2
  local opts=(-d "$domain" --log-level warn --profile "$profile")
  [[ $profile == *_secure ]] && opts+=(--identity "$creds/tool")
  "$bin/navbus" "${opts[@]}" latency pong --duration 120 "$@" >"$dir/$tag.pong.txt" 2>&1 &
  local pong=$!
  "$bin/navbus" "${opts[@]}" latency ping --samples "$samples" --warmup 200 --rate 200 "$@" \
    >"$dir/$tag.ping.txt" 2>&1 || true
  kill "$pong" 2>/dev/null || true
  wait "$pong" 2>/dev/null || true
  "$bin/navbus" "${opts[@]}" latency sink --duration 60 "$@" >"$dir/$tag.sink.txt" 2>&1 &
  local sink=$!
  "$bin/navbus" "${opts[@]}" latency flood --samples 20000 --warmup 1000 "$@" \
    >"$dir/$tag.flood.txt" 2>&1 || true
  if [ "$qos" = best_effort ]; then
    sleep 1
    kill -INT "$sink" 2>/dev/null || true  # a best-effort sink may miss the end of the stream
  fi
  wait "$sink" 2>/dev/null || true
  rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2>/dev/null || true
  domain=$((domain + 1))
}
for profile in "${profiles[@]}"; do
  echo "latency_sweep: $profile" >&2
  run_case "$profile" reliable
  run_case "$profile" best_effort --writer-profile navbus_latency_best_effort_writer \
    --reader-profile navbus_latency_best_effort_reader
done

/usr/bin/python3 - "$dir" "${profiles[@]}" <<'EOF'
import re, sys
d, profiles = sys.argv[1], sys.argv[2:]
num = r"([0-9.]+)"
print(f"{'participant profile':40} {'stream QoS':12} {'one way [us]: median':>20} {'p90':>7} {'p99':>7} "
      f"{'p99.9':>7} {'max':>8}  {'saturation [samples/s]':>22}  {'missing':>8}")
for p in profiles:
    for q in ("reliable", "best_effort"):
        ping = open(f"{d}/{p}.{q}.ping.txt").read()
        m = re.search(r"one way \[us\]\s+median " + num + r"\s+p90 " + num + r"\s+p99 " + num +
                      r"\s+p99.9 " + num + r"\s+max " + num, ping)
        lat = [f"{float(x):.0f}" for x in m.groups()] if m else ["-"] * 5
        flood = re.search(r"flood: .* in [0-9.]+ s: ([0-9]+) samples/s", open(f"{d}/{p}.{q}.flood.txt").read())
        sink = re.search(r"sink: took (\d+) samples.*: ([0-9]+) samples/s; missing (\d+)",
                         open(f"{d}/{p}.{q}.sink.txt").read())
        rate = flood.group(1) if flood else "-"
        if q == "best_effort" and sink:
            rate = f"{rate} written, {sink.group(2)} taken"
        missing = sink.group(3) if sink else "-"
        print(f"{p:40} {q:12} {lat[0]:>20} {lat[1]:>7} {lat[2]:>7} {lat[3]:>7} {lat[4]:>8}  {rate:>22}  {missing:>8}")
print(f"one way = half the round trip at 200 Hz; raw outputs: {d}")
EOF
