#!/usr/bin/env bash
# Installs the Debian 12 packages navbus needs, only those missing. Run as root.
# --package: only what building the package needs (the Docker image's build stage).
# --sanitizers adds clang and its sanitizer and libFuzzer runtimes (scripts/sanitize.sh).
set -euo pipefail
packages=(
  build-essential cmake pkg-config git ccache              # ccache: a rebuild of the same sources is quick
  libfastrtps-dev libfastcdr-dev fastddsgen                # Fast DDS 2.9, Fast-CDR, code generator
  python3                                                  # IDL schemas for MCAP recordings (idl/idl_schemas.py)
  libeigen3-dev libfftw3-dev libboost-dev                  # math (Boost.Math: noncentral chi-square); Boost.Beast (navbus foxglove)
  libyaml-cpp-dev libcli11-dev libspdlog-dev               # configuration, command line, logging
  libcsv-dev libtinyxml2-dev                               # CSV recordings (navbus replay), QoS files
  zlib1g-dev libzstd-dev                                   # MCAP recordings: CRC-32, zstd chunks
  nlohmann-json3-dev                                       # JSON of the Foxglove WebSocket bridge (navbus foxglove)
)
if [ "${1:-}" != --package ]; then
  packages+=(
    fastdds-tools                                          # Fast DDS CLI (discovery server)
    libgtest-dev libbenchmark-dev                          # tests and benchmarks
    cyclonedds-dev cyclonedds-tools                        # second DDS vendor for the interop test
    iproute2                                               # network namespaces for the topology test
    time                                                   # GNU time: peak RSS in scripts/bench.sh
    rtklib                                                 # rnx2rtkp: independent GPS fixes for the real-data test
    python3-matplotlib python3-yaml python3-numpy          # demo summary, figures, pseudorange errors (scripts/*.py)
    chromium                                               # a real browser opens the Foxglove bridge (tests/foxglove)
  )
fi
if [ "${1:-}" = --sanitizers ]; then
  packages+=(clang libclang-rt-14-dev llvm)          # ASan, UBSan, libFuzzer; llvm-symbolizer
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
