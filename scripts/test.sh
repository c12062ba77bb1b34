#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest, two at a time), then the compose
# demo in Docker with and without DDS Security (tests/docker: the engine, base images and
# images made as a user without registry access would), then the README's demo command from a
# fresh clone of the committed tree (tests/fresh_clone), then the
# sanitizer stage: the unit and integration tests and a slice of each fuzz target under
# AddressSanitizer and UndefinedBehaviorSanitizer (scripts/sanitize.sh, build-san/). Each
# stage prints how long it took.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
stage() {
  local name=$1 t0=$SECONDS
  shift
  "$@"
  echo "stage '$name': $((SECONDS - t0)) s (total $((SECONDS - start)) s)"
}
stage install bash scripts/install-deps.sh
stage build bash scripts/build.sh
stage ctest bash -c 'cd build && ctest --output-on-failure -j2 --timeout 300'
stage compose-demo bash tests/docker/run_compose_demo.sh build plain secure
stage fresh-clone-demo bash tests/fresh_clone/run_demo.sh
stage sanitizers bash scripts/sanitize.sh
