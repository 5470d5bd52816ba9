#!/usr/bin/env bash
# Runs a command with LCM confined to this machine's loopback:
#  - in a private network namespace (unshare -n as root, else unshare -rn) whose loopback has
#    multicast on and the route 224.0.0.0/4, with LCM_DEFAULT_URL=udpm://239.255.76.67:7667?ttl=0;
#    nothing outside sees the traffic, and parallel runs do not hear each other;
#  - when namespaces are not permitted: on the host with a port derived from the PID and ttl=0
#    (traffic stays on this host), and a note saying so.
#   scripts/lcm_netns.sh COMMAND [ARGS...]
# MESHNAV_NO_NETNS=1 forces the fallback. Exit code: the command's.
set -u
if (( $# == 0 )) || [[ $1 == -h || $1 == --help ]]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  exit $(( $# == 0 ? 2 : 0 ))
fi
if [[ "${MESHNAV_LCM_NETNS_INSIDE:-}" == 1 ]]; then
  unset MESHNAV_LCM_NETNS_INSIDE
  if ! { ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo; }; then
    echo "lcm_netns.sh: cannot enable multicast on the namespace's loopback" >&2
    exit 1
  fi
  export LCM_DEFAULT_URL="udpm://239.255.76.67:7667?ttl=0"
  echo "lcm_netns.sh: running in a private network namespace ($LCM_DEFAULT_URL)" >&2
  exec "$@"
fi
if [[ "${MESHNAV_NO_NETNS:-}" != 1 ]]; then
  for u in "unshare -n" "unshare -rn"; do
    if $u true 2> /dev/null; then
      exec $u env MESHNAV_LCM_NETNS_INSIDE=1 bash "$0" "$@"
    fi
  done
fi
port=$(( 20000 + ($$ % 20000) ))
export LCM_DEFAULT_URL="udpm://239.255.76.67:${port}?ttl=0"
echo "lcm_netns.sh: NOTE: no private network namespace here; using $LCM_DEFAULT_URL on the host" >&2
exec "$@"
