#!/usr/bin/env bash
# Runs a multi-host launch file (host: per process, config/launch/multihost.yaml) with every host in
# its own network namespace on this machine, as if each were its own computer on one Wi-Fi:
#  - one namespace per host plus one "switch" namespace; each host is joined to it by a veth pair
#    (host side eth0 10.77.0.N/16, multicast route 224.0.0.0/4 via eth0);
#  - LCM over udpm with ttl=1 (LCM_DEFAULT_URL=udpm://239.255.76.67:7667?ttl=1): a host's
#    datagrams leave through eth0 (its own processes also hear them locally, without faults);
#  - in the switch namespace meshnav_netem_switch forwards every datagram to every other host
#    through the fault model given by --netem, in tc netem's words ("loss 20% delay 20ms 10ms
#    duplicate 1% reorder 5%"), drawn independently per receiving host, and counts per LCM channel
#    what it received, lost, duplicated and delivered (LOGS/switch.yaml). (A Linux bridge with
#    `tc qdisc ... netem` on its ports would do the same; this machine's kernel has no netem
#    qdisc, and a userspace switch runs on any kernel that has network namespaces and veth.)
#  - each host's processes are started by scripts/supervisor.py --host NAME inside its namespace,
#    all with the same T0_UTIME; hosts whose processes stop by themselves (shutdown_after) are
#    waited for, then the others (e.g. the ground station) get SIGTERM; everything is torn down on
#    exit, also on Ctrl-C or an error.
#
#   scripts/multihost_netns.sh [options] LAUNCH.yaml VAR=value ...
#     --netem "SPEC"     faults of every link (default: none)
#     --seed N           seed of the faults (default 1)
#     --logs DIR         one log per host: DIR/HOST.log, and DIR/switch.log, DIR/switch.yaml
#                        (default: ./multihost_logs)
#     --t0-margin S      T0_UTIME = now + S (default 8: time for every host to start)
#     --timeout S        give up (exit 1) when the hosts still run after S seconds (default 3600)
#   BIN=DIR among the variables also locates meshnav_netem_switch (default build/bin).
#
# Needs root (ip netns) and iproute2. Exit codes: 0 when every host's supervisor exited 0,
# 1 otherwise, 2 bad arguments, 77 when namespaces cannot be created here (the reason is printed:
# tests skip on it). The host logs say "[supervisor] started NAME (pid N)": PIDs are this
# machine's (only the network is private), so a test can kill -9 one process.
set -u
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PY=/usr/bin/python3
[[ -x $PY ]] || PY=python3
NETEM=""
SEED=1
LOGS="$PWD/multihost_logs"
T0_MARGIN=8
TIMEOUT=3600
usage() { sed -n '2,33p' "$0" | sed 's/^# \{0,1\}//'; }
while (( $# )); do
  case "$1" in
    --netem) NETEM=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --logs) LOGS=$2; shift 2 ;;
    --t0-margin) T0_MARGIN=$2; shift 2 ;;
    --timeout) TIMEOUT=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    --*) echo "multihost_netns.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
(( $# >= 1 )) || { usage >&2; exit 2; }
LAUNCH=$1; shift
VARS=("$@")

skip() { echo "SKIP: $*"; exit 77; }
(( $(id -u) == 0 )) || skip "network namespaces need root (ip netns add); run as root"
command -v ip > /dev/null || skip "ip (iproute2) is not installed"
BIN="$ROOT/build/bin"
for v in "${VARS[@]}"; do [[ $v == BIN=* ]] && BIN=${v#BIN=}; done
SWITCH="$BIN/meshnav_netem_switch"
[[ -x "$SWITCH" ]] || { echo "multihost_netns.sh: $SWITCH is missing (build first)" >&2; exit 2; }

mapfile -t HOSTLINES < <("$PY" "$ROOT/scripts/supervisor.py" "$LAUNCH" "${VARS[@]}" --list-hosts) \
  || { echo "multihost_netns.sh: cannot read the hosts of $LAUNCH" >&2; exit 2; }
HOSTS=(); STOPS=()
for l in "${HOSTLINES[@]}"; do
  HOSTS+=("${l%% *}")
  STOPS+=("${l##* }")
done
(( ${#HOSTS[@]} > 0 )) || { echo "multihost_netns.sh: $LAUNCH names no host (host: per process)" >&2; exit 2; }
(( ${#HOSTS[@]} < 250 )) || { echo "multihost_netns.sh: too many hosts" >&2; exit 2; }

TAG="mh$$"
SW="$TAG-switch"
declare -A NS PID
CREATED=()
SWITCH_PID=""
cleanup() {
  trap - EXIT INT TERM
  local h p
  for h in "${!PID[@]}"; do
    p=${PID[$h]}
    kill -TERM "$p" 2> /dev/null
  done
  for h in "${!PID[@]}"; do
    p=${PID[$h]}
    for _ in $(seq 100); do kill -0 "$p" 2> /dev/null || break; sleep 0.1; done
    kill -KILL "$p" 2> /dev/null
  done
  stop_switch
  for n in "${CREATED[@]}"; do ip netns del "$n" 2> /dev/null; done
}
stop_switch() {  # SIGTERM: it writes its counters
  [[ -n "$SWITCH_PID" ]] || return 0
  kill -TERM "$SWITCH_PID" 2> /dev/null
  wait "$SWITCH_PID" 2> /dev/null
  SWITCH_PID=""
}
trap cleanup EXIT
trap 'exit 130' INT TERM

netns_add() {
  ip netns add "$1" 2> "$LOGS/.netns_error" || skip "cannot create network namespace $1: $(cat "$LOGS/.netns_error")"
  CREATED+=("$1")
  ip -n "$1" link set lo up
  # Datagrams come from addresses of other links: no reverse-path filtering.
  ip netns exec "$1" sh -c 'for f in /proc/sys/net/ipv4/conf/*/rp_filter; do echo 0 > "$f"; done'
}
mkdir -p "$LOGS"
netns_add "$SW"
PORTS=""
i=0
for h in "${HOSTS[@]}"; do
  i=$((i + 1))
  ns="$TAG-$h"
  NS[$h]=$ns
  netns_add "$ns"
  ip -n "$ns" link add eth0 type veth peer name "p$i" netns "$SW" || { echo "multihost_netns.sh: veth for $h" >&2; exit 1; }
  ip -n "$SW" addr add "10.77.$((100 + i / 250)).$((i % 250 + 1))/16" dev "p$i"
  ip -n "$SW" link set "p$i" multicast on
  ip -n "$SW" link set "p$i" up
  ip -n "$ns" addr add "10.77.$((i / 250)).$((i % 250 + 1))/16" dev eth0
  ip -n "$ns" link set eth0 multicast on
  ip -n "$ns" link set eth0 up
  ip -n "$ns" route add 224.0.0.0/4 dev eth0
  PORTS+="${PORTS:+,}p$i"
done
# The switch stands for the network, which in a real deployment does not share the hosts' CPUs:
# it runs at real-time priority (else nice -10) so that a loaded machine (two cores, eleven hosts,
# other work) does not hold datagrams in its queue. Without it, a CI run had the switch 9.5 s
# behind: ranges reached the estimator 12 s late (RANGE:time_behind), the mission's CALIB_CMD of
# t = 100 s reached the calibrator after the run. Its lag is counted in switch.yaml ("behind").
PRIO=()
if chrt -f 10 true 2> /dev/null; then PRIO=(chrt -f 10); elif nice -n -10 true 2> /dev/null; then PRIO=(nice -n -10); fi
ip netns exec "$SW" "${PRIO[@]}" "$SWITCH" --ports "$PORTS" --netem "$NETEM" --seed "$SEED" --summary "$LOGS/switch.yaml" \
  > "$LOGS/switch.log" 2>&1 &
SWITCH_PID=$!
for _ in $(seq 100); do
  grep -q "ports, group" "$LOGS/switch.log" 2> /dev/null && break
  kill -0 "$SWITCH_PID" 2> /dev/null || { cat "$LOGS/switch.log" >&2; echo "multihost_netns.sh: the switch did not start" >&2; SWITCH_PID=""; exit 2; }
  sleep 0.05
done
URL="udpm://239.255.76.67:7667?ttl=1"
T0=$(( $(date +%s%6N) + ${T0_MARGIN%.*} * 1000000 ))
echo "multihost: ${#HOSTS[@]} hosts in namespaces $TAG-*, switch in $SW (${PRIO[*]:-normal priority}), LCM $URL, netem: ${NETEM:-none}, T0_UTIME $T0, logs $LOGS/"
for h in "${HOSTS[@]}"; do
  ip netns exec "${NS[$h]}" env LCM_DEFAULT_URL="$URL" "$PY" "$ROOT/scripts/supervisor.py" "$LAUNCH" \
    --host "$h" "${VARS[@]}" T0_UTIME="$T0" > "$LOGS/$h.log" 2>&1 &
  PID[$h]=$!
  echo "multihost: host $h: supervisor pid ${PID[$h]}, log $LOGS/$h.log"
done

# Wait for the hosts that stop by themselves, then stop the others.
start=$(date +%s)
rc=0
declare -A DONE
remaining() {
  local n=0 k
  for k in "${!HOSTS[@]}"; do
    [[ ${STOPS[$k]} == stops && -z "${DONE[${HOSTS[$k]}]:-}" ]] && n=$((n + 1))
  done
  echo $n
}
collect() {  # reaps hosts that exited; $1 = also the "runs" hosts
  local k h code
  for k in "${!HOSTS[@]}"; do
    h=${HOSTS[$k]}
    [[ -n "${DONE[$h]:-}" ]] && continue
    if ! kill -0 "${PID[$h]}" 2> /dev/null; then
      wait "${PID[$h]}"; code=$?
      DONE[$h]=$code
      unset "PID[$h]"
      echo "multihost: host $h finished with exit code $code"
      (( code == 0 )) || rc=1
    fi
  done
}
while (( $(remaining) > 0 )); do
  collect
  if (( $(date +%s) - start > TIMEOUT )); then
    echo "multihost: hosts still running after $TIMEOUT s; stopping everything"
    exit 1
  fi
  sleep 0.2
done
for h in "${!PID[@]}"; do
  echo "multihost: stopping host $h (it runs until stopped)"
  kill -TERM "${PID[$h]}" 2> /dev/null
done
while (( ${#PID[@]} > 0 )); do
  collect
  (( $(date +%s) - start > TIMEOUT + 30 )) && { echo "multihost: hosts do not stop"; exit 1; }
  sleep 0.1
done
stop_switch
echo "multihost: done (exit $rc); datagrams per channel: $LOGS/switch.yaml"
exit $rc
