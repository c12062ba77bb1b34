#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest, two at a time), then the
# README's demo command from a fresh clone of the committed tree (tests/fresh_clone), then the
# sanitizer stage: the unit and integration tests and a slice of each fuzz target under
# AddressSanitizer and UndefinedBehaviorSanitizer (scripts/sanitize.sh, build-san/).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
(cd build && ctest --output-on-failure -j2 --timeout 300)
bash tests/fresh_clone/run_demo.sh
bash scripts/sanitize.sh
