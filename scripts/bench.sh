#!/usr/bin/env bash
# Runs every benchmark and prints one table: each figure beside the baseline measured in the
# same run (or the issue's absolute target), and the raw outputs under $BENCH_DIR.
#   bash scripts/bench.sh            (builds first if needed; about 8 minutes on 2 cores)
# Environment: BENCH_DIR (default: a new temporary directory), BENCH_DOMAIN (DDS domain of the
# latency ping/pong, default 150), BENCH_RUNS (offline repetitions, default 3).
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/bin/navbus ] && [ -x build/bin/navbus_pipeline_benchmark ] || bash scripts/build.sh
dir=${BENCH_DIR:-$(mktemp -d)}
mkdir -p "$dir"
domain=${BENCH_DOMAIN:-150}
runs=${BENCH_RUNS:-3}
bin=build/bin

echo "bench: engine benchmark (60000 IMU cycles per configuration, 3 runs)" >&2
for i in 1 2 3; do
  "$bin/navbus_engine_benchmark" sim/scenarios 60000 >"$dir/engine_$i.txt" 2>&1
done
echo "bench: filter pipeline (validation, ordered merge, history, engine, messages)" >&2
"$bin/navbus_pipeline_benchmark" . 40000 >"$dir/pipeline.txt" 2>&1
echo "bench: GLR and dither benchmarks" >&2
"$bin/navbus_glr_benchmark" >"$dir/glr.txt" 2>&1
"$bin/navbus_dither_benchmark" >"$dir/dither.txt" 2>&1

echo "bench: navbus offline, seed 001, 3600 s, $runs runs" >&2
for i in $(seq "$runs"); do
  /usr/bin/time -f "%e %M" -o "$dir/offline_time_$i.txt" \
    "$bin/navbus" --log-level warn offline --scenario sim/scenarios/seed001_leo.yaml \
    --filter config/filter_seed001_lc.yaml --duration 3600 --start config -o "$dir/offline"
done

# Both at the IMU rate (200 Hz). Three rounds, each the raw ping (2000 samples) right before
# the end-to-end run (2000 increments): the machine's state drifts over minutes, so each
# ratio compares runs seconds apart, and the verdict takes the median of the three ratios.
echo "bench: raw Fast DDS ping/pong and navbus-filter fed by navbus latency imu, 200 Hz, 3 rounds, domains $domain, $((domain + 1))" >&2
"$bin/navbus" -d "$domain" --log-level warn latency pong --duration 120 >"$dir/pong.txt" 2>&1 &
pong=$!
"$bin/navbus-filter" -c config/filter_latency.yaml -d "$((domain + 1))" --log-level warn \
  >"$dir/filter.txt" 2>&1 &
filter=$!
for i in 1 2 3; do
  "$bin/navbus" -d "$domain" --log-level warn latency ping --samples 2000 --warmup 200 --rate 200 \
    --csv "$dir/ping_$i.csv" >"$dir/ping_$i.txt" 2>&1 || true
  "$bin/navbus" -d "$((domain + 1))" --log-level warn latency imu --samples 2000 --warmup 200 \
    --rate 200 --csv "$dir/e2e_$i.csv" >"$dir/e2e_$i.txt" 2>&1 || true
done
cp "$dir/ping_1.csv" "$dir/ping.csv"
cp "$dir/e2e_1.csv" "$dir/e2e.csv"
# Peak resident memory of the filter participant over the runs.
grep -E "VmHWM|RssAnon|RssFile" "/proc/$filter/status" >"$dir/filter_rss.txt" 2>/dev/null || true
# Proportional set size: shared-library pages divided among the processes that map them.
grep -E "^Pss:" "/proc/$filter/smaps_rollup" >>"$dir/filter_rss.txt" 2>/dev/null || true
kill -INT "$filter" 2>/dev/null || true
kill "$pong" 2>/dev/null || true
wait "$filter" "$pong" 2>/dev/null || true
rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2>/dev/null || true
# A navigator's scheduled load: seed 001 in real time (IMU 200 Hz, raw 200 Hz, GNSS epochs
# and fixes 10 Hz, star tracker 5 Hz), the filter with the low-latency output, the fault
# manager, and a passive observer: IMU source time stamp -> outputs received.
echo "bench: scheduled load, seed 001 in real time (25 s), observed end to end, domain $((domain + 4))" >&2
printf 'extends: %s\nlow_latency_output: {enabled: true}\n' "$PWD/config/filter_seed001_lc.yaml" \
  >"$dir/filter_seed001_low_latency.yaml"
"$bin/navbus-filter" -c "$dir/filter_seed001_low_latency.yaml" -d "$((domain + 4))" --log-level warn \
  >"$dir/load_filter.txt" 2>&1 &
load_filter=$!
"$bin/navbus-fault-manager" -c config/fault_manager.yaml -d "$((domain + 4))" --log-level warn \
  >"$dir/load_fm.txt" 2>&1 &
load_fm=$!
"$bin/navbus" -d "$((domain + 4))" --log-level warn latency observe --samples 4000 --warmup 200 \
  --duration 60 --csv "$dir/observe.csv" >"$dir/observe.txt" 2>&1 &
observer=$!
"$bin/navbus-sensor-sim" -c sim/scenarios/seed001_leo.yaml -d "$((domain + 4))" --pacing realtime \
  --duration 25 --log-level warn >"$dir/load_sim.txt" 2>&1 || true
wait "$observer" 2>/dev/null || true
kill -INT "$load_filter" "$load_fm" 2>/dev/null || true
wait "$load_filter" "$load_fm" 2>/dev/null || true

echo "bench: raw Fast DDS saturation, one stream, navbus sensor QoS (flood -> sink), domain $((domain + 2))" >&2
"$bin/navbus" -d "$((domain + 2))" --log-level warn latency sink --duration 120 >"$dir/sink.txt" 2>&1 &
sink=$!
"$bin/navbus" -d "$((domain + 2))" --log-level warn latency flood --samples 50000 --warmup 2000 \
  >"$dir/flood.txt" 2>&1 || true
wait "$sink" 2>/dev/null || true
# The same with the simulator's fast-pacing writer (asynchronous publication): the raw figure
# with the writer QoS the bus throughput below is measured with.
"$bin/navbus" -d "$((domain + 2))" --log-level warn latency sink --duration 120 >"$dir/sink_async.txt" 2>&1 &
sink=$!
"$bin/navbus" -d "$((domain + 2))" --log-level warn latency flood --samples 50000 --warmup 2000 \
  --writer-profile navbus_sensor_writer_fast_pacing >"$dir/flood_async.txt" 2>&1 || true
wait "$sink" 2>/dev/null || true

# The seed-001 stream mix (IMU 200 Hz, raw 200 Hz, GNSS epochs and fixes 10 Hz, star tracker
# 5 Hz), 600 s of data in fast pacing through the three participants: the simulator prints the
# time from its first write to the last acknowledgment. Three runs with the scenario's blocks
# (timing.fast_pacing_block_s, 0.3 s: 60 increments, 3 GNSS epochs and fixes, 1-2 attitudes a
# sample), three with 0.1 s blocks (one epoch a sample), one with one measurement per sample
# (--fast-pacing-block 0) for comparison.
throughput() {  # tag, domain, simulator options...
  local tag=$1 d=$2
  shift 2
  "$bin/navbus-filter" -c config/filter_seed001_lc.yaml -d "$d" >"$dir/tp_filter_$tag.txt" 2>&1 &
  local tp_filter=$!
  "$bin/navbus-fault-manager" -c config/fault_manager.yaml -d "$d" >"$dir/tp_fm_$tag.txt" 2>&1 &
  local tp_fm=$!
  "$bin/navbus-sensor-sim" -c sim/scenarios/seed001_leo.yaml -d "$d" --duration 600 "$@" \
    >"$dir/tp_sim_$tag.txt" 2>&1 || true
  sleep 1
  kill -INT "$tp_filter" "$tp_fm" 2>/dev/null || true
  wait "$tp_filter" "$tp_fm" 2>/dev/null || true
  rm -f /dev/shm/fastrtps_* /dev/shm/sem.fastrtps_* 2>/dev/null || true
}
echo "bench: bus throughput, seed 001, 600 s of data, fast pacing, three processes, domain $((domain + 3))" >&2
for i in 1 2 3; do throughput "$i" "$((domain + 3))"; done
for i in 1 2 3; do throughput "block01_$i" "$((domain + 3))" --fast-pacing-block 0.1; done
throughput single "$((domain + 3))" --fast-pacing-block 0

echo "bench: raw latency and saturation per participant profile and stream QoS (scripts/latency_sweep.sh)" >&2
SWEEP_DIR="$dir/sweep" SWEEP_DOMAIN="$((domain + 20))" NAVBUS_BIN="$bin" bash scripts/latency_sweep.sh 2000 \
  >"$dir/sweep.txt" 2>/dev/null || echo "bench: latency sweep failed (see $dir/sweep)" >&2

/usr/bin/python3 scripts/plot_navbus.py latency --raw "$dir/ping.csv" --e2e "$dir/e2e.csv" -o "$dir" \
  >/dev/null 2>&1 || echo "bench: no latency figure (see the CSV files in $dir)" >&2

/usr/bin/python3 - "$dir" "$runs" <<'EOF'
import re, statistics, sys
d, runs = sys.argv[1], int(sys.argv[2])
rows = []
def row(figure, value, reference, verdict=""):
    rows.append((figure, value, reference, verdict))

engines = [open(f"{d}/engine_{i}.txt").read() for i in (1, 2, 3)]
def us(label):
    """(us/cycle, ratio, allocations) of a row: medians over the three runs."""
    found = [re.search(re.escape(label) + r"\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)", e) for e in engines]
    if not all(found):
        return None
    return tuple(statistics.median(float(m.group(k)) for m in found) for k in (1, 2, 3))
base = us("mechanization + covariance (base)")
if base:
    row("engine: mechanization + covariance, seed 001 (median of 3)", f"{base[0]:.2f} us/cycle",
        "target <= 2 us", "met" if base[0] <= 2.0 else "NOT met")
    row("engine: heap allocations per cycle", f"{base[2]:.3f}", "target 0",
        "met" if base[2] == 0 else "NOT met")
for label in ("loosely coupled, centralized", "loosely coupled, federated",
              "tightly coupled (pseudoranges)"):
    v = us(label)
    if v:
        row(f"engine: {label}", f"{v[0]:.2f} us/cycle", f"{v[1]:.2f} x base")
v = us("tightly coupled, covariance 0.10 s")
if v:
    row("engine: tightly coupled, covariance every 0.1 s (ekf.covariance_period_s)",
        f"{v[0]:.2f} us/cycle", "target <= 1.0 us", "met" if v[0] <= 1.0 else "NOT met")
v = us("aligned start + protection levels")
if v:
    row("engine: aligned start + protection levels, seed 000", f"{v[0]:.2f} us/cycle",
        f"{v[1]:.3f} x configured start", "met (<= 1.20)" if v[1] <= 1.2 else "NOT met (> 1.20)")

pipe = re.search(r"([0-9.]+) us per cycle, ([0-9.]+) heap allocations per cycle, ([0-9]+) of the cycles",
                 open(f"{d}/pipeline.txt").read())
if pipe:
    row("filter pipeline (participant path without DDS), per IMU cycle",
        f"{pipe.group(1)} us, {pipe.group(2)} allocs", "target 0 allocations",
        "met" if int(pipe.group(3)) == 0 else f"NOT met ({pipe.group(3)} cycles allocated)")

times, rss = [], []
for i in range(1, runs + 1):
    t, m = open(f"{d}/offline_time_{i}.txt").read().split()[-2:]
    times.append(float(t)); rss.append(int(m) / 1024.0)
med = statistics.median(times)
row(f"offline seed 001, 3600 s (median of {runs})", f"{med:.2f} s", "target < 2 s",
    "met" if med < 2.0 else "NOT met")
row("offline peak RSS", f"{max(rss):.1f} MiB", "")

glr = re.search(r"seed 001 LEO: 12 satellites\s+12.0\s+20\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)",
                open(f"{d}/glr.txt").read())
if glr:
    row("GLR per epoch, 12 satellites, M = 20", f"{float(glr.group(3)):.1f} us",
        f"{float(glr.group(3)) / float(glr.group(2)):.2f} x the TC update; target <= 50 us",
        "met" if float(glr.group(3)) <= 50 else "NOT met")
arm = re.search(r"seed 001 LEO: 12 sats, arm\s+12.0\s+20\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)",
                open(f"{d}/glr.txt").read())
if arm:
    ratio = float(arm.group(3)) / float(arm.group(2))
    row("GLR per epoch with a lever arm, 12 satellites, M = 20", f"{float(arm.group(3)):.1f} us",
        f"{ratio:.2f} x the TC update; target <= 1x", "met" if ratio <= 1.0 else "NOT met")
parity = re.search(r"two per IMU epoch \(gyros, accelerometers\): ([0-9.]+) us", open(f"{d}/glr.txt").read())
if parity:
    row("parity detector, 3 triads, per IMU epoch", f"{parity.group(1)} us", "target <= 5 us",
        "met" if float(parity.group(1)) <= 5 else "NOT met")
dither = re.search(r"monitor\s+([0-9.]+) s\s+=\s+([0-9.]+) % of one core", open(f"{d}/dither.txt").read())
if dither:
    row("dither monitor, share of one core", f"{dither.group(2)} %", "target < 1 %",
        "met" if float(dither.group(2)) < 1 else "NOT met")

stat = r"median\s+([0-9.]+)\s+p90\s+([0-9.]+)\s+p99\s+([0-9.]+)\s+p99.9\s+([0-9.]+)\s+max\s+([0-9.]+)"
def stats(pattern, text):
    m = re.search(pattern + r"\s+" + stat, text)
    return (float(m.group(1)), float(m.group(3))) if m else None
rounds = []
for i in (1, 2, 3):
    e = open(f"{d}/e2e_{i}.txt").read()
    rounds.append((stats(r"round trip \[us\]", open(f"{d}/ping_{i}.txt").read()),
                   stats(r"low-latency output", e), stats(r"deterministic solution", e),
                   stats(r"increment -> filter's write", e),
                   stats(r"filter's write -> received", e)))
ok = [r for r in rounds if r[0] and r[1] and r[2]]
rt = None
if ok:
    med = lambda xs: statistics.median(xs)
    rt = (med([r[0][0] for r in ok]), med([r[0][1] for r in ok]))
    row(f"raw Fast DDS two hops (round trip), 200 Hz, median / p99 (median of {len(ok)} rounds)",
        f"{rt[0]:.0f} / {rt[1]:.0f} us", "baseline")
    ratios_m = [r[1][0] / r[0][0] for r in ok]
    ratios_p = [r[1][1] / r[0][1] for r in ok]
    m, p = med(ratios_m), med(ratios_p)
    row("IMU -> low-latency output received, median / p99 (median of the rounds)",
        f"{med([r[1][0] for r in ok]):.0f} / {med([r[1][1] for r in ok]):.0f} us",
        f"{m:.2f} / {p:.2f} x two hops of the same round (rounds: "
        + ", ".join(f"{a:.2f}/{b:.2f}" for a, b in zip(ratios_m, ratios_p)) + "); target <= 1.25 / 2",
        "met" if m <= 1.25 and p <= 2.0 else "NOT met")
    split = [r for r in ok if r[3] and r[4]]
    if split:
        row("  of which: increment written -> the filter's write of the output (hop 1, wake-up, pipeline)",
            f"{med([r[3][0] for r in split]):.0f} us median", "")
        row("  of which: the filter's write -> received (the write call and hop 2)", f"{med([r[4][0] for r in split]):.0f} us median",
            f"raw one hop ~ {rt[0] / 2:.0f} us")
    row("IMU -> deterministic solution received, median / p99",
        f"{med([r[2][0] for r in ok]):.0f} / {med([r[2][1] for r in ok]):.0f} us",
        f"{med([r[2][0] / r[0][0] for r in ok]):.2f} / {med([r[2][1] / r[0][1] for r in ok]):.2f} x two hops "
        "(IMU-only filter: written after the low-latency output of the same increment)")
else:
    row("raw Fast DDS two hops / IMU -> outputs", "no result", f"see {d}/ping_*.txt, {d}/e2e_*.txt")

obs = open(f"{d}/observe.txt").read()
obs_fast = re.search(r"low-latency output\s+" + stat, obs)
obs_det = re.search(r"deterministic solution\s+" + stat, obs)
if rt and obs_fast and obs_det:
    row("scheduled load (seed 001 real time, 3 participants): IMU -> low-latency output, median / p99",
        f"{float(obs_fast.group(1)):.0f} / {float(obs_fast.group(3)):.0f} us",
        f"{float(obs_fast.group(1)) / rt[0]:.2f} / {float(obs_fast.group(3)) / rt[1]:.2f} x two hops")
    row("scheduled load: IMU -> deterministic solution (waits for the GNSS fix and star tracker of its instant)",
        f"{float(obs_det.group(1)):.0f} / {float(obs_det.group(3)):.0f} us",
        f"{float(obs_det.group(1)) / rt[0]:.2f} / {float(obs_det.group(3)) / rt[1]:.2f} x two hops")
else:
    row("scheduled load, observed", "no result", f"see {d}/observe.txt")

flood_re = r"flood: \d+ samples .* in ([0-9.]+) s: ([0-9]+) samples/s"
flood = re.search(flood_re, open(f"{d}/flood.txt").read())
flood_async = re.search(flood_re, open(f"{d}/flood_async.txt").read())
sink = re.search(r"missing (\d+)", open(f"{d}/sink.txt").read())
tp_re = r"\(([0-9.]+)x real time\): ([0-9]+) samples/s, ([0-9]+) measurements/s"
def throughput(tag):
    m = re.search(tp_re, open(f"{d}/tp_sim_{tag}.txt").read())
    f = re.search(r"increments integrated (\d+)", open(f"{d}/tp_filter_{tag}.txt").read())
    return (float(m.group(1)), int(m.group(2)), int(m.group(3)),
            int(f.group(1)) if f else -1) if m else None
runs_tp = [r for r in (throughput(i) for i in (1, 2, 3)) if r]
runs_tp01 = [r for r in (throughput(f"block01_{i}") for i in (1, 2, 3)) if r]
single = throughput("single")
tp = sorted(runs_tp)[len(runs_tp) // 2] if runs_tp else None  # the median run by x real time
tp01 = sorted(runs_tp01)[len(runs_tp01) // 2] if runs_tp01 else None
if flood:
    row("raw Fast DDS saturation, one stream, reliable sensor QoS",
        f"{int(flood.group(2))} samples/s", f"baseline; sink missing {sink.group(1) if sink else '?'}")
else:
    row("raw Fast DDS saturation", "no result", f"see {d}/flood.txt")
if flood_async:
    row("raw Fast DDS saturation, the simulator's asynchronous fast-pacing writer",
        f"{int(flood_async.group(2))} samples/s", "second baseline (the bus's own writer QoS)")
if tp:
    row(f"bus throughput, seed 001 mix, 600 s, three processes, fast pacing (median of {len(runs_tp)})",
        f"{tp[0]:.1f}x real time", "target >= 400x", "met" if tp[0] >= 400 else "NOT met")
    for label, t in (("blocks of 0.3 s, the default", tp), ("blocks of 0.1 s", tp01)):
        if not t:
            continue
        if t is tp01:
            row(f"bus throughput with {label} (median of {len(runs_tp01)})", f"{t[0]:.1f}x real time", "")
        if flood:
            ratio = t[2] / int(flood.group(2))
            row(f"bus throughput, measurements/s ({label})", f"{t[2]} ({t[1]} samples/s)",
                f"{ratio:.2f} x raw saturation; target >= 10", "met" if ratio >= 10 else "NOT met")
        if flood_async:
            ratio = t[2] / int(flood_async.group(2))
            row(f"bus throughput, measurements/s against the asynchronous writer's raw saturation ({label})",
                f"{t[2]}", f"{ratio:.2f} x; target >= 10", "met" if ratio >= 10 else "NOT met")
    every = runs_tp + runs_tp01
    row("bus throughput: increments the filter integrated (every run)",
        ", ".join(str(r[3]) for r in every), "of 120000 published (zero loss)",
        "met" if all(r[3] == 120000 for r in every) and len(every) == 6 else "NOT met")
else:
    row("bus throughput, seed 001", "no result", f"see {d}/tp_sim_*.txt")
if single:
    row("bus throughput, one increment per DDS sample (--fast-pacing-block 0)",
        f"{single[0]:.1f}x real time, {single[2]} measurements/s",
        f"{single[2] / int(flood.group(2)):.2f} x raw saturation" if flood else "",
        "zero loss" if single[3] == 120000 else f"NOT zero loss ({single[3]})")

try:
    kib = {k: int(v.split()[0]) for k, v in
           (line.split(":", 1) for line in open(f"{d}/filter_rss.txt").read().splitlines())}
    hwm_kib = kib["VmHWM"]
    row("navbus-filter peak RSS (latency run, low-latency output on)", f"{hwm_kib / 1024:.1f} MiB",
        "target < 15 MB", "met" if hwm_kib * 1024 < 15e6 else "NOT met")
    row("navbus-filter RSS at the end: private (anonymous) / shared-library pages",
        f"{kib['RssAnon'] / 1024:.1f} / {kib['RssFile'] / 1024:.1f} MiB",
        "library pages are shared by every Fast DDS process on the host")
    if "Pss" in kib:
        row("navbus-filter proportional set size at the end (shared pages divided among their users)",
            f"{kib['Pss'] / 1024:.1f} MiB", "")
except (OSError, IndexError, ValueError, KeyError):
    row("navbus-filter peak RSS", "not read", f"see {d}/filter_rss.txt")

w = [max(len(r[i]) for r in rows + [("figure", "value", "baseline / target", "")]) for i in range(4)]
fmt = "  ".join(f"{{:<{x}}}" for x in w)
print(fmt.format("figure", "value", "baseline / target", ""))
for r in rows:
    print(fmt.format(*r))
print()
try:
    print(open(f"{d}/sweep.txt").read().rstrip())
except OSError:
    print("latency sweep: no result")
print(f"raw outputs and the latency figure (latency.png): {d}")
EOF
