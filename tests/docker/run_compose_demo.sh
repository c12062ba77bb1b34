#!/usr/bin/env bash
# The compose demo as a user runs it: docker/docker-compose.yml up --build, then checks what the
# user would look at: the summary shows both faults decided and the filter's commands applied,
# the figures were written, and every container exited 0. --secure adds
# docker/docker-compose.secure.yml (DDS Security, each service with only its own identity).
#
# It uses the Docker engine that runs, or installs Debian's docker.io and docker-compose, starts
# dockerd (overlay2 where the kernel allows it, else vfs) and stops it at the end. Base images
# the engine cannot pull are made from the Debian mirror (scripts/docker-base-images.sh). The
# images are built from the package this build installed (NAVBUS_PACKAGE=prebuilt, the default
# here: the compile was tested by the build stage) or compiled in the image build
# (NAVBUS_PACKAGE=source, what a user's `up --build` does). Containers, network and the images
# it built (tagged test-<pid>) are removed afterwards; the base images are kept.
# Usage: run_compose_demo.sh BUILD_DIR [--secure]...   Exits 77 where no engine can run.
set -euo pipefail
build=$(cd "${1:?usage: run_compose_demo.sh BUILD_DIR [--secure]}" && pwd)
shift
src=$(cd "$(dirname "$0")/../.." && pwd)
modes=("$@")
[ ${#modes[@]} -gt 0 ] || modes=(plain)
export NAVBUS_PACKAGE=${NAVBUS_PACKAGE:-prebuilt}
export NAVBUS_TAG=test-$$
work=$(mktemp -d /tmp/navbus-compose.XXXXXX)
started_engine=0
t0=$SECONDS
say() { echo "[compose-demo $((SECONDS - t0)) s] $*"; }

# --- the engine ---------------------------------------------------------------------------
# The demo itself goes through scripts/compose.sh, the README's command, which picks a docker
# client with BuildKit on whatever PATH this test inherits.
start_engine() {
  if ! command -v dockerd > /dev/null || ! command -v docker-compose > /dev/null; then
    say "installing docker.io and docker-compose (Debian 12)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      docker.io docker-compose > "$work/apt.log" 2>&1 || { tail -20 "$work/apt.log"; exit 77; }
  fi
  local driver
  for driver in overlay2 vfs; do
    dockerd --storage-driver="$driver" > "$work/dockerd.log" 2>&1 &
    echo $! > "$work/dockerd.pid"
    for _ in $(seq 60); do
      docker info > /dev/null 2>&1 && { started_engine=1; say "dockerd started ($driver)"; return; }
      kill -0 "$(cat "$work/dockerd.pid")" 2> /dev/null || break
      sleep 0.5
    done
    kill "$(cat "$work/dockerd.pid")" 2> /dev/null || true
    wait "$(cat "$work/dockerd.pid")" 2> /dev/null || true
  done
  tail -20 "$work/dockerd.log"
  echo "SKIP: no Docker engine could be started here"
  exit 77
}
if docker info > /dev/null 2>&1; then
  say "using the running Docker engine"
else
  [ "$(id -u)" = 0 ] || { echo "SKIP: no Docker engine runs, and starting one needs root"; exit 77; }
  start_engine
fi
if ! docker compose version > /dev/null 2>&1 && ! command -v docker-compose > /dev/null; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends docker-compose
fi
compose=(bash "$src/scripts/compose.sh")
# The images' own user (as before the wrapper, which defaults to the caller's ids), and no
# ./navbus-out in the checkout: each run below mounts its own output directory.
export NAVBUS_UID=10001 NAVBUS_GID=10001 NAVBUS_OUT_DIR=$work

project=navbus-test-$$
cleanup() {
  local mode
  for mode in plain secure; do
    "${compose[@]}" --secure -p "$project-$mode" \
      down --volumes --remove-orphans > /dev/null 2>&1 || true
  done
  docker rmi "navbus:$NAVBUS_TAG" "navbus-report:$NAVBUS_TAG" > /dev/null 2>&1 || true
  docker image prune -f > /dev/null 2>&1 || true
  if [ $started_engine = 1 ]; then
    kill "$(cat "$work/dockerd.pid")" 2> /dev/null || true
    wait "$(cat "$work/dockerd.pid")" 2> /dev/null || true
    say "dockerd stopped"
  fi
  rm -rf "$work" "$src/build/docker-prefix"
}
trap cleanup EXIT
current_project=  # the compose project of the mode under test
fail() {
  echo "FAIL: $*"
  tail -60 "$work/compose.log" 2> /dev/null || true
  # Every container's state and the end of its log: which one did not finish, and why.
  local c
  for c in $(docker ps -aq --filter "label=com.docker.compose.project=$current_project"); do
    echo "--- $(docker inspect -f '{{.Name}}: {{.State.Status}}, exit code {{.State.ExitCode}}' "$c")"
    docker logs --tail 40 "$c" 2>&1 || true
  done
  exit 1
}

# --- base images and the package ----------------------------------------------------------
bash "$src/scripts/docker-base-images.sh"
if [ "$NAVBUS_PACKAGE" = prebuilt ]; then
  rm -rf "$src/build/docker-prefix"
  cmake --install "$build" --prefix "$src/build/docker-prefix" --strip > "$work/install.log"
  # The image takes bin/ and share/ only: leave the SDK out of the build context.
  rm -rf "$src/build/docker-prefix/lib" "$src/build/docker-prefix/include"
fi

# --- the demo, once per mode --------------------------------------------------------------
run_demo() {  # MODE
  local mode=$1 out=$work/out-$1 extra=()
  current_project=$project-$mode
  mkdir -p "$out"
  chown 10001:10001 "$out"   # the images' user writes the recordings and figures
  if [ "$mode" = secure ]; then
    # Each service's identity, readable by the images' user only.
    cp -r "$build/security" "$work/security"
    chown -R 10001:10001 "$work/security"
    export NAVBUS_SECURITY_DIR=$work/security
    extra=(--secure)
  fi
  say "$mode: ${compose[*]} up --build (NAVBUS_PACKAGE=$NAVBUS_PACKAGE)"
  local t=$SECONDS rc=0
  NAVBUS_OUT_DIR=$out timeout 600 "${compose[@]}" "${extra[@]}" -p "$project-$mode" \
    up --build > "$work/compose.log" 2>&1 || rc=$?
  say "$mode: up returned $rc after $((SECONDS - t)) s"
  [ $rc -eq 0 ] || fail "$mode: compose up exited $rc"
  # Every container of the project, with its exit code.
  local states
  states=$(docker ps -a --filter "label=com.docker.compose.project=$project-$mode" \
    --format '{{.Names}} {{.Status}}')
  echo "$states"
  [ "$(echo "$states" | grep -c .)" -ge 7 ] || fail "$mode: expected 7 containers"
  if echo "$states" | grep -v "Exited (0)"; then fail "$mode: a container did not exit 0"; fi
  local summary=$out/summary.txt
  docker logs "$(docker ps -aq --filter "label=com.docker.compose.project=$project-$mode" \
    --filter label=com.docker.compose.service=summary)" > "$summary" 2>&1
  grep -q "navbus demo summary" "$summary" || fail "$mode: no summary"
  [ "$(grep -c '^ *decision [0-9]* at' "$summary")" -ge 2 ] || fail "$mode: fewer than 2 decisions"
  ! grep -q "NOT DETECTED" "$summary" || fail "$mode: a fault was not detected"
  grep -q "filter: .*commands applied [1-9]" "$summary" || fail "$mode: the filter applied no command"
  ls "$out/figures/"*.png > /dev/null 2>&1 || fail "$mode: no figures in $out/figures"
  # The simulator announced the end of its streams: no stream may have been called lost.
  grep -q "end of data: 0 stream-lost decisions" "$summary" || fail "$mode: a stream was called lost"
  grep -E "^ *decision [0-9]* at|^fault [0-9]|^end of data" "$summary"
  say "$mode: ok ($(ls "$out/figures/"*.png | wc -l) figures)"
  "${compose[@]}" "${extra[@]}" -p "$project-$mode" down --volumes > /dev/null 2>&1
}
for mode in "${modes[@]}"; do
  case $mode in
    plain|--plain) run_demo plain ;;
    secure|--secure) run_demo secure ;;
    *) echo "unknown mode '$mode' (--secure)"; exit 2 ;;
  esac
done
docker images --format '{{.Repository}}:{{.Tag}} {{.Size}}' | grep -E "^navbus(-report)?:$NAVBUS_TAG "
size=$(docker image inspect -f '{{.Size}}' "navbus:$NAVBUS_TAG")
say "runtime image navbus:$NAVBUS_TAG: $((size / 1000000)) MB (target < 150 MB)"
# Nothing to compile with in the participants' image.
if docker run --rm --entrypoint sh "navbus:$NAVBUS_TAG" -c \
  'command -v cc gcc g++ c++ python3; dpkg -l | grep -E "^ii +[^ ]+-dev[: ]"'; then
  fail "the runtime image holds a compiler, Python or a -dev package"
fi
[ "$size" -lt 150000000 ] || fail "the runtime image is $((size / 1000000)) MB, not < 150 MB"
[ "$(docker run --rm --entrypoint id "navbus:$NAVBUS_TAG" -u)" != 0 ] || fail "the image runs as root"
say "compose demo: ok"
