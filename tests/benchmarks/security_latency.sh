#!/usr/bin/env bash
# Benchmark: the latency cost of DDS Security as a ratio, measured in one run. `navbus latency`
# pings at 200 Hz (the IMU rate) between two processes over UDP loopback, alternating the plain
# profile and the secure one (signed sensor-class topic, PKI-DH, access control) for ROUNDS
# rounds; prints each run and the ratio of the medians of the secure runs' figures to the
# plain runs'. Fails only if a run cannot match or loses a ping (no timing assertion).
# Usage: security_latency.sh NAVBUS_EXE CREDENTIALS_DIR [SAMPLES] [ROUNDS]   (domain 92)
set -euo pipefail
exe="$1"; creds="$2"; samples="${3:-1000}"; rounds="${4:-2}"
domain=92
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() {  # name, then the participant options
  local name=$1; shift
  "$exe" -d $domain --log-level warn "$@" latency pong --duration 60 > "$out/pong.log" 2>&1 &
  local pong=$!
  if ! "$exe" -d $domain --log-level warn "$@" latency ping --samples "$samples" --rate 200 \
      > "$out/$name.txt" 2>&1; then
    cat "$out/$name.txt" "$out/pong.log"; kill $pong; exit 1
  fi
  kill -TERM $pong; wait $pong || true
  echo "$name: $(grep '^round trip' "$out/$name.txt")"
  grep '^round trip' "$out/$name.txt" | awk -v n="$name" '{print n, $5, $7, $9}' >> "$out/all"
}
for r in $(seq "$rounds"); do
  run plain
  run secure --profile navbus_participant_udp_loopback_secure --identity "$creds/tool"
done
python3 - "$out/all" <<'PY'
import sys, statistics
rows = [l.split() for l in open(sys.argv[1])]
fig = {k: [[float(r[i]) for r in rows if r[0] == k] for i in (1, 2, 3)] for k in ("plain", "secure")}
med = {k: [statistics.median(v) for v in fig[k]] for k in fig}
print("median over %d runs each, round trip [us]: plain median %.0f p90 %.0f p99 %.0f; "
      "secure median %.0f p90 %.0f p99 %.0f" % (len(fig["plain"][0]), *med["plain"], *med["secure"]))
print("latency cost of DDS Security (secure / plain): median x%.2f, p90 x%.2f, p99 x%.2f"
      % tuple(s / p for s, p in zip(med["secure"], med["plain"])))
PY
