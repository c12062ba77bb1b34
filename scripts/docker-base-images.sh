#!/usr/bin/env bash
# Makes the base images docker/Dockerfile starts from (debian:12 and debian:12-slim) when the
# Docker engine has neither and cannot pull them (no registry access): a minimal Debian 12 root
# file system from this machine's Debian mirror (debootstrap --variant=minbase), imported as
# both tags. Images the engine already has, or can pull, are left as they are. Run as root.
#   bash scripts/docker-base-images.sh            # make only what is missing
#   NAVBUS_DEBIAN_MIRROR=http://... bash scripts/docker-base-images.sh
set -euo pipefail
tags=(debian:12-slim debian:12)
missing=()
for tag in "${tags[@]}"; do
  docker image inspect "$tag" > /dev/null 2>&1 && continue
  if timeout 60 docker pull -q "$tag" > /dev/null 2>&1; then
    echo "docker-base-images: pulled $tag"
  else
    missing+=("$tag")
  fi
done
[ ${#missing[@]} -eq 0 ] && { echo "docker-base-images: ${tags[*]} present"; exit 0; }

# The mirror apt uses on this machine, unless given.
mirror=${NAVBUS_DEBIAN_MIRROR:-}
if [ -z "$mirror" ]; then
  mirror=$(grep -hs -m1 -oP '^(URIs:\s*|deb\s+(\[[^]]*\]\s+)?)\Khttps?://\S+/debian/?(?=\s|$)' \
    /etc/apt/sources.list.d/*.sources /etc/apt/sources.list.d/*.list /etc/apt/sources.list |
    head -1 || true)
  mirror=${mirror:-http://deb.debian.org/debian}
fi
command -v debootstrap > /dev/null || {
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap
}
root=$(mktemp -d /tmp/navbus-debian12.XXXXXX)
trap 'rm -rf "$root"' EXIT
echo "docker-base-images: ${missing[*]} not available; debootstrap bookworm from $mirror"
debootstrap --variant=minbase bookworm "$root" "$mirror" > "$root.log" 2>&1 ||
  { tail -20 "$root.log"; rm -f "$root.log"; exit 1; }
rm -f "$root.log"
# As the official slim image: no downloaded packages, package lists, documentation or
# translations, and dpkg told to leave them out of what is installed later.
rm -rf "$root"/var/cache/apt/archives/*.deb "$root"/var/cache/apt/*.bin \
  "$root"/var/lib/apt/lists/* "$root"/usr/share/doc/* "$root"/usr/share/man/* \
  "$root"/usr/share/info/* "$root"/usr/share/locale/*
cat > "$root/etc/dpkg/dpkg.cfg.d/navbus-slim" <<'CFG'
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/info/*
path-exclude /usr/share/locale/*
path-exclude /usr/share/lintian/*
CFG
tar -C "$root" -c . | docker import -c 'CMD ["bash"]' - "${missing[0]}" > /dev/null
for tag in "${missing[@]:1}"; do docker tag "${missing[0]}" "$tag"; done
echo "docker-base-images: made ${missing[*]} ($(docker image inspect -f '{{.Size}}' "${missing[0]}" |
  awk '{printf "%.0f MB", $1 / 1e6}'))"
