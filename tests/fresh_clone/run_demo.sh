#!/usr/bin/env bash
# The README's demo command from a fresh clone of the committed tree (HEAD), as a new user
# runs it: a clean directory with no build/, ../shared beside it when the checkout has one.
# Fails if the demo fails or its summary lacks what it promises. Uncommitted changes are not
# part of a clone: the script says so when the working tree is dirty.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
if [ -n "$(git -C "$src" status --porcelain --untracked-files=no)" ]; then
  echo "fresh-clone demo: note: uncommitted changes in $src are not tested (only HEAD is cloned)"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git clone -q "$src" "$work/main"
[ -d "$src/../shared" ] && cp -r "$src/../shared" "$work/shared"
cd "$work/main"
# A domain of its own, so that a concurrent run on the default domain 0 cannot interfere.
if ! NAVBUS_DEMO_DOMAIN=${NAVBUS_DEMO_DOMAIN:-90} bash scripts/demo.sh > "$work/demo.out" 2>&1; then
  echo "fresh-clone demo: FAILED"; tail -60 "$work/demo.out"; exit 1
fi
cat "$work/demo.out"
for expected in "navbus demo summary" "sensor-sim:" "filter:" "fault-manager:" "recorder:"; do
  grep -q "$expected" "$work/demo.out" || { echo "fresh-clone demo: summary lacks '$expected'"; exit 1; }
done
echo "fresh-clone demo: passed"
