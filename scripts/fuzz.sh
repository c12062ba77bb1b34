#!/usr/bin/env bash
# Runs the libFuzzer targets (a sanitizer build made by scripts/sanitize.sh, or any build
# configured with -DNAVBUS_BUILD_FUZZERS=ON) for a given number of executions each:
#   navbus_fuzz_topics  CDR deserialization of every topic type + the input validators
#   navbus_fuzz_config  the configuration parsers (participant, simulator, filter, fault manager)
#   navbus_fuzz_foxglove  the Foxglove bridge's handling of client messages
# Seeds: a valid sample of each topic type and the shipped configurations; the corpus grows in
# the work directory and is reused by the next run. A crash, leak, undefined behaviour or
# violated property fails the script and leaves the input under <work>/artifacts.
# --parallel runs the two targets side by side (one core each) instead of one after the other;
# --only topics|config|foxglove runs one of them.
#
#   bash scripts/fuzz.sh [--bin build-san/bin] [--runs 10000000] [--work build-san/fuzz]
#                        [--parallel] [--only topics|config|foxglove]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$root/build-san/bin
runs=10000000
work=""
parallel=0
only=""
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --parallel) parallel=1; shift ;;
    --only) only=$2; shift 2 ;;
    *) echo "fuzz.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
work=${work:-$bin/../fuzz}
case "$only" in
  ""|topics|config|foxglove) ;;
  *) echo "fuzz.sh: --only '$only': expected topics, config or foxglove" >&2; exit 2 ;;
esac
for t in navbus_fuzz_topics navbus_fuzz_config navbus_fuzz_foxglove navbus_fuzz_seeds; do
  [ -x "$bin/$t" ] || { echo "fuzz.sh: $bin/$t missing: build with scripts/sanitize.sh first" >&2; exit 2; }
done
mkdir -p "$work/corpus/topics" "$work/corpus/config" "$work/corpus/foxglove" "$work/artifacts"
seeds=()
for f in "$root"/config/filter*.yaml; do seeds+=("filter:$f"); done
for f in "$root"/config/fault_manager*.yaml; do seeds+=("fault:$f"); done
for f in "$root"/sim/scenarios/*.yaml; do seeds+=("sim:$f"); done
seeds+=("participant:$root/config/filter.yaml")
mkdir -p "$work/seeds/topics" "$work/seeds/config" "$work/seeds/foxglove"
"$bin/navbus_fuzz_seeds" "$work/seeds" "${seeds[@]}"
# The bridge's clients: what Foxglove sends, and one of each refusal, 0x00 between messages.
printf '{"op":"subscribe","subscriptions":[{"id":0,"channelId":1},{"id":1,"channelId":2}]}\0{"op":"unsubscribe","subscriptionIds":[0]}' \
  > "$work/seeds/foxglove/subscribe"
printf '{"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]}\0{"op":1}\0[]\0\001abc\0{' \
  > "$work/seeds/foxglove/refusals"

# LeakSanitizer on; the first finding stops the target. malloc_context_size=0: ASan keeps every
# distinct allocation stack for the life of the process, and the parsers' recursion makes new ones
# all the time (measured: +1.3 KB per execution of navbus_fuzz_config, so 10 M executions would
# pass -rss_limit_mb; flat without the stacks, and 23 % faster). quarantine_size_mb=32 (default
# 256): freed memory is still held back long enough to catch a use after free inside one
# execution, and the peak RSS drops from 470 to under 100 MB. A finding's stacks: replay the
# artifact, which runs with ASan's default options.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:malloc_context_size=0:quarantine_size_mb=32}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
run() {  # target corpus max_len; returns 1 on a finding
  local log=$work/$1.log
  echo "fuzz.sh: $1, $runs executions (log $log)"
  if ! "$bin/$1" -runs="$runs" -max_len="$3" -print_final_stats=1 -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$work/artifacts/$1-" "$work/corpus/$2" "$work/seeds/$2" > "$log" 2>&1; then
    echo "fuzz.sh: $1 FAILED"; grep -E "ERROR|SUMMARY|==[0-9]+==|runtime error|Test unit written" "$log" | head -20
    return 1
  fi
  local execs rate rss
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log")
  echo "fuzz.sh: $1 passed: $execs executions, $rate per second, peak RSS $rss MB," \
    "corpus $(ls "$work/corpus/$2" | wc -l) inputs, 0 crashes"
}
status=0
if [ -n "$only" ]; then
  case "$only" in
    topics) run navbus_fuzz_topics topics 65536 || status=1 ;;
    config) run navbus_fuzz_config config 8192 || status=1 ;;
    foxglove) run navbus_fuzz_foxglove foxglove 1024 || status=1 ;;
  esac
elif [ "$parallel" = 1 ]; then
  run navbus_fuzz_topics topics 65536 & topics=$!
  run navbus_fuzz_config config 8192 & config=$!
  wait "$topics" || status=1
  wait "$config" || status=1
  run navbus_fuzz_foxglove foxglove 1024 || status=1
else
  run navbus_fuzz_topics topics 65536 || status=1
  run navbus_fuzz_config config 8192 || status=1
  run navbus_fuzz_foxglove foxglove 1024 || status=1
fi
exit $status
