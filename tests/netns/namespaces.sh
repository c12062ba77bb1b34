# Sourced by the network-namespace tests: one namespace per host, each with one veth into a
# bridge that lives in its own "switch" namespace, so nothing touches the host's interfaces.
# Multicast (SPDP discovery) leaves through eth0; the bridge is the whole network.
#   netns_available            exits 77 (skipped) where namespaces cannot be created
#   netns_create ID SUBNET H.. creates nb<H><ID> at 10.254.SUBNET.n and the switch nbsw<ID>
#   netns_delete ID H..        removes them

netns_available() {
  local probe="nbprobe$$"
  if ! ip netns add "$probe" 2>/dev/null; then
    echo "SKIP: network namespaces are not permitted here (ip netns add failed)"
    exit 77
  fi
  ip netns del "$probe"
}

netns_create() {
  local id=$1 subnet=$2
  shift 2
  local sw="nbsw$id" n=1 h ns
  ip netns add "$sw"
  ip netns exec "$sw" ip link add br0 type bridge mcast_snooping 0
  ip netns exec "$sw" ip link set br0 up
  for h in "$@"; do
    ns="nb$h$id"
    ip netns add "$ns"
    ip link add "v$h$id" type veth peer name "s$h$id"
    ip link set "v$h$id" netns "$ns"
    ip link set "s$h$id" netns "$sw"
    ip netns exec "$sw" ip link set "s$h$id" master br0 up
    ip netns exec "$ns" ip link set "v$h$id" name eth0
    ip netns exec "$ns" ip addr add "10.254.$subnet.$n/24" dev eth0
    ip netns exec "$ns" ip link set eth0 up
    ip netns exec "$ns" ip link set lo up
    ip netns exec "$ns" ip route add 224.0.0.0/4 dev eth0
    n=$((n + 1))
  done
}

netns_delete() {
  local id=$1 h
  shift
  for h in "$@"; do ip netns del "nb$h$id" 2>/dev/null || true; done
  ip netns del "nbsw$id" 2>/dev/null || true
}
