#!/usr/bin/env bash
# The compose demo's command, for any PATH: picks a docker client that can build with BuildKit,
# then runs compose on docker/docker-compose.yml (and docker/docker-compose.secure.yml with
# --secure) with the arguments given, for example
#
#   bash scripts/compose.sh up --build
#   bash scripts/compose.sh --secure up --build
#
# Why: docker-compose 1.29 builds through the `docker` client first on PATH. Debian's docker.io
# 20.10 client has BuildKit built in; clients from 23.0 on need the buildx plugin for it, and
# without the plugin `up --build` stops at once ("BuildKit is enabled but the buildx component
# is missing"). This script takes the first client on PATH that has buildx or is older than 23,
# and says which. It also sets the variables the compose file reads (NAVBUS_UID and NAVBUS_GID:
# yours; NAVBUS_OUT_DIR: navbus-out/ in the checkout, made here) unless they are set already.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
files=(-f "$root/docker/docker-compose.yml")
if [ "${1:-}" = --secure ]; then
  files+=(-f "$root/docker/docker-compose.secure.yml")
  shift
fi

client_version() {  # DOCKER: the client's version (the daemon need not run)
  "$1" version --format '{{.Client.Version}}' 2> /dev/null | head -1 || true
}
builds_with_buildkit() {  # DOCKER
  "$1" buildx version > /dev/null 2>&1 && return 0
  local major
  major=$(client_version "$1" | cut -d. -f1)
  [[ "$major" =~ ^[0-9]+$ ]] && [ "$major" -lt 23 ]
}
chosen=""
seen=()
while IFS= read -r candidate; do
  real=$(readlink -f "$candidate")
  [[ " ${seen[*]:-} " == *" $real "* ]] && continue
  seen+=("$real")
  if builds_with_buildkit "$candidate"; then
    chosen=$candidate
    break
  fi
  echo "compose.sh: skipping $candidate (client $(client_version "$candidate"):" \
    "no buildx plugin for BuildKit)" >&2
done < <(type -ap docker)
if [ -z "$chosen" ]; then
  echo "compose.sh: no docker client on PATH can build with BuildKit; install Debian's" \
    "docker.io and docker-compose (apt-get install docker.io docker-compose) or the buildx" \
    "plugin for your client" >&2
  exit 1
fi
echo "compose.sh: docker client $chosen ($(client_version "$chosen"))" >&2
export PATH=$(dirname "$chosen"):$PATH DOCKER_BUILDKIT=1 COMPOSE_DOCKER_CLI_BUILD=1
export NAVBUS_UID=${NAVBUS_UID:-$(id -u)} NAVBUS_GID=${NAVBUS_GID:-$(id -g)}
if [ -z "${NAVBUS_OUT_DIR:-}" ]; then
  export NAVBUS_OUT_DIR=$root/navbus-out
  mkdir -p "$NAVBUS_OUT_DIR"
fi

if docker compose version > /dev/null 2>&1; then
  exec docker compose "${files[@]}" "$@"
elif command -v docker-compose > /dev/null; then
  exec docker-compose "${files[@]}" "$@"
fi
echo "compose.sh: neither 'docker compose' nor docker-compose is installed" \
  "(apt-get install docker-compose)" >&2
exit 1
