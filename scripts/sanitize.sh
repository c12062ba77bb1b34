#!/usr/bin/env bash
# The sanitizer stage: builds navbus with clang, AddressSanitizer and UndefinedBehaviorSanitizer
# (any undefined behaviour aborts) into ./build-san, with the libFuzzer targets; runs the unit
# and integration tests under them and a bounded slice of each fuzz target (ctest fuzz_smoke_*:
# scripts/fuzz.sh, 100000 executions each). Benchmarks and the CPU-load timing tests are left to
# the normal build: the sanitizers change the timing they measure.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh --sanitizers
mkdir -p build-san
t0=$SECONDS
launcher=()
if command -v ccache > /dev/null; then
  # As scripts/build.sh: cached by content, paths relative to the checkout.
  export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
  # The normal and the sanitizer builds together need about 7 GB (ccache's default is 5 GB).
  export CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-12G}
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
# Line tables only: the sanitizers' stack traces keep file and line, and the build of the
# Eigen-heavy sources does not carry full debug information (their largest cost here). A unity
# build (8 sources a unit; the test programs whose files share helper names are left out in
# tests/) parses the Eigen and Fast DDS headers once per unit: about 9 instead of 15 minutes
# on 2 cores without a cache.
CC=clang CXX=clang++ cmake -S . -B build-san -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8 \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
  -DNAVBUS_SANITIZE=address,undefined -DNAVBUS_BUILD_FUZZERS=ON \
  -DNAVBUS_BUILD_BENCHMARKS=OFF -DNAVBUS_BUILD_INTEROP=OFF "${launcher[@]}" \
  > build-san/configure.log 2>&1 ||
  { cat build-san/configure.log; exit 1; }
cmake --build build-san -j"$(nproc)"
echo "sanitizers: build $((SECONDS - t0)) s"
t0=$SECONDS
# Leaks are reported at each process's exit; a report fails the test that ran it.
# new_delete_type_mismatch=0: libfastrtps 2.9.1 frees an 88-byte object of its own as a
# 56-byte one in RTPSWriter::~RTPSWriter (sized delete in a library navbus does not build).
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:new_delete_type_mismatch=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Left to the normal build: cpu_load, fault_loop_load and lanes_load (timing under CPU load, which the
# sanitizers change), figures (Python plotting; the runs it plots are the real_car and
# unit_evaluation tests here) and mcap_foxglove (two recorders of one fast-paced run compared
# message by message: under ASan only 1 of the 1,200 IMU blocks and 400 of the 1,200 solutions
# of the MCAP file matched a row of the CSV recording by source time stamp, not yet explained;
# unit_records runs the MCAP writer and reader here), and foxglove_load (three fast-paced runs
# to compare the simulator's throughput with and without the bridge: a timing measurement;
# foxglove_bridge runs the bridge here).
(cd build-san && ctest --output-on-failure -j2 --timeout 600 \
  -E "^(cpu_load|fault_loop_load|lanes_load|figures|mcap_foxglove|foxglove_load)$")
echo "sanitizers: tests $((SECONDS - t0)) s"
