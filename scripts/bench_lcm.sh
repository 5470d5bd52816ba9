#!/usr/bin/env bash
# ./meshnav bench lcm: the estimator over LCM on this machine (issue 38 item 6). A simulated
# sequence is played in real time (or --rate X) by imu_bridge and uwb_bridge into the estimator
# process, inside a private network namespace (scripts/lcm_netns.sh); meshnav_lcm_probe receives
# IMU, RANGE and POSE and reports IMU -> POSE and RANGE -> POSE latency (median, p99, max; what
# each is: transport/latency_recorder.h) and messages per second; the CPU of each process is read
# from /proc/PID/stat (user + system time over its wall time). Options:
#   --seed N               paper-scenario sequence (default 1)
#   --duration-scale S     length of the flight, as meshnav_sim's (default 0.5: 70 s)
#   --rate X               playback speed (default 1: real time, the figures that matter)
#   --out DIR              work folder (default out/bench-lcm); DIR/bench_lcm.yaml holds the figures
# One vehicle only: a fleet over LCM (channel prefixes) does not exist yet (docs/fleet.md).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${MESHNAV_BUILD_DIR:-$ROOT/build}/bin"
seed=1; scale=0.5; rate=1; out="$ROOT/out/bench-lcm"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seed) seed="$2"; shift 2 ;;
    --duration-scale) scale="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench_lcm: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
if [[ -z "${MESHNAV_BENCH_LCM_INSIDE:-}" ]]; then
  export MESHNAV_BENCH_LCM_INSIDE=1
  exec bash "$ROOT/scripts/lcm_netns.sh" bash "$0" --seed "$seed" --duration-scale "$scale" --rate "$rate" --out "$out"
fi
mkdir -p "$out"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -KILL "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "bench_lcm: $*" >&2; for f in "$out"/*.log; do echo "---- $f" >&2; tail -n 8 "$f" >&2; done; exit 1; }
now_us() { date +%s%6N; }
# cpu_s PID: user + system CPU seconds of a running process.
cpu_s() { awk -v hz="$(getconf CLK_TCK)" '{ print ($14 + $15) / hz }' "/proc/$1/stat"; }

echo "[bench lcm] simulate seed $seed (duration scale $scale)" >&2
"$BIN/meshnav_sim" --seed "$seed" --duration-scale "$scale" --out "$out/data" > "$out/sim.log" 2>&1 || fail "meshnav_sim failed"
"$BIN/estimator" --setup "$out/data/setup.yaml" --heartbeat 0.2 > "$out/estimator.log" 2>&1 &
EST=$!; PIDS+=("$EST")
"$BIN/meshnav_lcm_probe" --out "$out/probe.yaml" > "$out/probe.log" 2>&1 &
PROBE=$!; PIDS+=("$PROBE")
t_start=$(now_us)
T0=$(( t_start + 2000000 ))
echo "[bench lcm] play at ${rate}x from t0 = $T0 us (estimator, bridges, probe in $LCM_DEFAULT_URL)" >&2
for b in imu_bridge uwb_bridge; do
  "$BIN/$b" --dataset "$out/data" --rate "$rate" --t0-utime "$T0" --wait-for ESTIMATOR_STATUS --wait-timeout 30 \
    --progress 10 > "$out/$b.log" 2>&1 &
  PIDS+=("$!")
done
IMU=${PIDS[2]}; UWB=${PIDS[3]}
cpu_imu=0; cpu_uwb=0
while kill -0 "$IMU" 2>/dev/null || kill -0 "$UWB" 2>/dev/null; do
  kill -0 "$IMU" 2>/dev/null && cpu_imu=$(cpu_s "$IMU")
  kill -0 "$UWB" 2>/dev/null && cpu_uwb=$(cpu_s "$UWB")
  sleep 0.5
done
wait "$IMU" || fail "imu_bridge failed"
wait "$UWB" || fail "uwb_bridge failed"
sleep 0.5  # the estimator's last POSE on its way (bounded; nothing is waited for beyond it)
t_end=$(now_us)
kill -0 "$EST" 2>/dev/null || fail "the estimator exited before the end of the data (estimator.log)"
cpu_est=$(cpu_s "$EST"); cpu_probe=$(cpu_s "$PROBE")
kill -TERM "$PROBE"; wait "$PROBE" || fail "meshnav_lcm_probe failed"
kill -TERM "$EST"; wait "$EST" || fail "estimator exited with $? on SIGTERM"
wall_s=$(awk -v a="$t_start" -v b="$t_end" 'BEGIN { print (b - a) / 1e6 }')
{
  echo "# ./meshnav bench lcm, $(date -u +%Y-%m-%dT%H:%M:%SZ), seed $seed, duration scale $scale, rate ${rate}x, $(nproc) cores"
  cat "$out/probe.yaml"
  echo "cpu_percent_of_a_core:  # user + system over the ${wall_s} s of wall time from the estimator's start"
  for p in estimator:$cpu_est imu_bridge:$cpu_imu uwb_bridge:$cpu_uwb lcm_probe:$cpu_probe; do
    awk -v n="${p%%:*}" -v c="${p#*:}" -v w="$wall_s" 'BEGIN { printf "  %s: %.2f\n", n, 100 * c / w }'
  done
} > "$out/bench_lcm.yaml"
cat "$out/bench_lcm.yaml"
grep -q "imu_to_pose: {n: 0," "$out/bench_lcm.yaml" && fail "no POSE answered an IMU sample: the estimator never initialized?"
# A run whose estimator stopped or failed measured something else than the estimator at work.
if grep -q "\] \[error\]" "$out/estimator.log"; then
  grep "\] \[error\]" "$out/estimator.log" | head -n 3 >&2
  fail "the estimator reported an error: these figures are not the estimator's at work"
fi
exit 0
