#!/usr/bin/env bash
# Two "hosts" on one machine, for lab 04's multi-host test: two network namespaces joined by
# a virtual Ethernet cable (a veth pair), each with its own address and, for what runs in it
# through this script, its own host name. OpenMPI sees two machines and talks TCP between
# them; what it would run over ssh it runs through `agent` below. Needs root (CAP_NET_ADMIN
# and CAP_SYS_ADMIN).
#
#   netns_hosts.sh up PREFIX            create the hosts PREFIX-a and PREFIX-b
#   netns_hosts.sh down PREFIX          end what still runs in them and remove them
#   netns_hosts.sh run ADDRESS CMD...   run CMD on the host with that address
#   netns_hosts.sh agent ADDRESS CMD    OpenMPI's launch agent, ssh's stand-in
#                                       (--mca plm_rsh_agent): CMD is one shell string
# run and agent find PREFIX in $RT_NETNS_PREFIX.
#
# The hosts: PREFIX-a is 10.213.0.1/24, named PREFIX-a; PREFIX-b is 10.213.0.2/24, named
# PREFIX-b. Nothing outside the two namespaces is touched: no address, route or file of this
# machine changes.
set -euo pipefail

ADDRESS_A=10.213.0.1
ADDRESS_B=10.213.0.2

usage() {
    sed -n '2,/^set /p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
    exit 2
}

# The namespace of a host address, given the prefix.
namespace_of() {
    case "$1" in
        "$ADDRESS_A") echo "$2-a" ;;
        "$ADDRESS_B") echo "$2-b" ;;
        *) echo "netns_hosts.sh: no host with address '$1' (expected $ADDRESS_A or $ADDRESS_B)" >&2
           exit 2 ;;
    esac
}

prefix_from_env() {
    if [ -z "${RT_NETNS_PREFIX:-}" ]; then
        echo "netns_hosts.sh: RT_NETNS_PREFIX is not set" >&2
        exit 2
    fi
    echo "$RT_NETNS_PREFIX"
}

cmd=${1:-}
shift || true
case "$cmd" in
    up)
        [ $# -eq 1 ] || usage
        p=$1
        ip netns add "$p-a"
        ip netns add "$p-b"
        # The interfaces are created in the namespaces directly, so their names cannot clash
        # with this machine's.
        ip link add veth0 netns "$p-a" type veth peer name veth0 netns "$p-b"
        ip -n "$p-a" addr add "$ADDRESS_A/24" dev veth0
        ip -n "$p-b" addr add "$ADDRESS_B/24" dev veth0
        for ns in "$p-a" "$p-b"; do
            ip -n "$ns" link set lo up
            ip -n "$ns" link set veth0 up
        done
        ;;
    down)
        [ $# -eq 1 ] || usage
        p=$1
        for ns in "$p-a" "$p-b"; do
            # Whatever still runs there was started through this script (orted daemons of a
            # failed run); end those processes, by their ids, then the namespace.
            for pid in $(ip netns pids "$ns" 2>/dev/null); do kill "$pid" 2>/dev/null || true; done
            ip netns del "$ns" 2>/dev/null || true
        done
        ;;
    run)
        [ $# -ge 2 ] || usage
        p=$(prefix_from_env)
        ns=$(namespace_of "$1" "$p")
        shift
        # shellcheck disable=SC2016  # $0 and $@ belong to the inner shell
        exec ip netns exec "$ns" unshare --uts sh -c 'hostname "$0" && exec "$@"' "$ns" "$@"
        ;;
    agent)
        # ssh HOST COMMAND...: the words of COMMAND form one shell command line.
        [ $# -ge 2 ] || usage
        p=$(prefix_from_env)
        ns=$(namespace_of "$1" "$p")
        shift
        exec ip netns exec "$ns" unshare --uts sh -c "hostname $ns && $*"
        ;;
    *)
        usage
        ;;
esac
