#!/usr/bin/env bash
# Publishers are known (issue 36 item 4): the real processes over udpm in a private network
# namespace (scripts/lcm_netns.sh).
#  1. An estimator and a logger run; a second estimator started on the same network hears the
#     first's ESTIMATOR_STATUS (its sender started before it) and exits 7 with a message naming
#     the channel; the first keeps running. A second logger into the same --out exits 7 naming
#     the folder and the first one's pid (common/dir_lock.h).
#  2. The bridges then replay a simulated flight at 10x: the logger's estimate.csv has one row per
#     POSE of the one estimator, in time order; the logger and the first estimator counted the
#     second one's heartbeat as a second publisher of ESTIMATOR_STATUS (summary.yaml).
#  3. The supervisor refuses a second launch of the same launch file: its estimator exits 7, is not
#     restarted, the launch exits 1 with "refused to run", and the first launch's processes run on.
#   second_instance_test.sh BIN_DIR WORK_DIR
# Waits are on conditions (a log line, a process exit, file contents), each bounded.
set -u
BIN=$(cd "$1" && pwd)
WORK=$2
SRC=$(cd "$(dirname "$0")/../.." && pwd)
if [[ -z "${MESHNAV_SECOND_INSIDE:-}" ]]; then
  export MESHNAV_SECOND_INSIDE=1
  exec bash "$SRC/scripts/lcm_netns.sh" bash "$0" "$@"
fi
rm -rf "$WORK"
mkdir -p "$WORK"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -KILL -- "$p" 2>/dev/null; kill -KILL "$p" 2>/dev/null; done; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$WORK"/*.log; do echo "---- $f (last lines)"; tail -n 12 "$f"; done
  exit 1
}
now_us() { date +%s%6N; }
# wait_for FILE PATTERN SECONDS WHAT
wait_for() {
  local start; start=$(now_us)
  until grep -q -- "$2" "$1" 2>/dev/null; do
    (( $(now_us) - start < $3 * 1000000 )) || fail "$4 (no '$2' in $1 after $3 s)"
    sleep 0.05
  done
}
# wait_exit PID NAME SECONDS: waits for the process to exit; returns its exit code.
wait_exit() {
  local pid=$1 start; start=$(now_us)
  while kill -0 "$pid" 2>/dev/null; do
    (( $(now_us) - start < $3 * 1000000 )) || fail "$2 still running after $3 s"
    sleep 0.05
  done
  wait "$pid"
}

echo "== simulate a short flight"
"$BIN/meshnav_sim" --seed 2 --out "$WORK/data" > "$WORK/sim.log" 2>&1 || fail "meshnav_sim"

echo "== 1. first estimator and logger; then a second estimator on the same network"
"$BIN/estimator" --setup "$WORK/data/setup.yaml" --heartbeat 0.2 > "$WORK/estimator_1.log" 2>&1 &
EST=$!; PIDS+=($EST)
"$BIN/logging" --out "$WORK/lcm" --flush-period 0.2 > "$WORK/logging.log" 2>&1 &
LOG=$!; PIDS+=($LOG)
wait_for "$WORK/estimator_1.log" "strategy" 20 "the first estimator did not start"
"$BIN/estimator" --setup "$WORK/data/setup.yaml" --heartbeat 0.2 > "$WORK/estimator_2.log" 2>&1 &
EST2=$!; PIDS+=($EST2)
wait_exit "$EST2" "the second estimator" 20; rc=$?
(( rc == 7 )) || fail "the second estimator exited with $rc, not 7"
grep -q "another instance already runs" "$WORK/estimator_2.log" || fail "the second estimator did not say why"
grep -q "ESTIMATOR_STATUS is published by instance" "$WORK/estimator_2.log" || fail "no channel named"
kill -0 "$EST" 2>/dev/null || fail "the first estimator stopped too"
"$BIN/logging" --out "$WORK/lcm" > "$WORK/logging_2.log" 2>&1; rc=$?
(( rc == 7 )) || fail "a second logger into the same --out exited with $rc, not 7"
grep -q -- "--out $WORK/lcm is in use by another process (pid $LOG)" "$WORK/logging_2.log" \
  || fail "the second logger did not name the folder and the first logger's pid"
echo "second estimator: exit 7, $(grep -o 'channel ESTIMATOR_STATUS is published.*)' "$WORK/estimator_2.log" | head -1)"

echo "== 2. replay at 10x into the first estimator"
T0=$(( $(now_us) + 1500000 ))
for b in imu_bridge uwb_bridge; do
  "$BIN/$b" --dataset "$WORK/data" --rate 10 --t0-utime $T0 --wait-for ESTIMATOR_STATUS --wait-timeout 30 \
    > "$WORK/$b.log" 2>&1 &
  PIDS+=($!)
done
wait_exit "${PIDS[3]}" imu_bridge 120; rc=$?; (( rc == 0 )) || fail "imu_bridge exited with $rc"
wait_exit "${PIDS[4]}" uwb_bridge 120; rc=$?; (( rc == 0 )) || fail "uwb_bridge exited with $rc"
last_imu_t=$(tail -n 1 "$WORK/data/imu.csv" | cut -d, -f1)
start=$(now_us)
while true; do
  last_est_t=$(tail -n 1 "$WORK/lcm/estimate.csv" 2>/dev/null | cut -d, -f1)
  if [[ "$last_est_t" =~ ^[0-9.]+$ ]] && awk -v a="$last_est_t" -v b="$last_imu_t" 'BEGIN{exit !(a >= b - 0.05)}'; then break; fi
  (( $(now_us) - start < 30000000 )) || fail "estimate.csv stopped at t = ${last_est_t:-none} (< $last_imu_t)"
  sleep 0.1
done
kill -TERM "$EST"; wait_exit "$EST" estimator 20; rc=$?; (( rc == 0 )) || fail "the first estimator exited with $rc"
kill -TERM "$LOG"; wait_exit "$LOG" logging 20; rc=$?; (( rc == 0 )) || fail "logging exited with $rc"
n_pose=$(sed -n 's/^  POSE: {messages: \([0-9]*\),.*/\1/p' "$WORK/lcm/summary.yaml")
n_rows=$(( $(wc -l < "$WORK/lcm/estimate.csv") - 1 ))
[[ -n "$n_pose" ]] || fail "no POSE count in summary.yaml"
(( n_rows == n_pose )) || fail "estimate.csv has $n_rows rows for $n_pose POSE"
awk -F, 'NR > 2 && $1 <= prev { bad = 1 } NR > 1 { prev = $1 } END { exit bad }' "$WORK/lcm/estimate.csv" \
  || fail "estimate.csv is not in time order"
grep -q "ESTIMATOR_STATUS:second_publisher" "$WORK/lcm/summary.yaml" \
  || fail "the second estimator's heartbeat was not counted as a second publisher"
echo "estimate.csv: $n_rows rows for $n_pose POSE, in time order; $(grep -o 'ESTIMATOR_STATUS:second_publisher: [0-9]*' "$WORK/lcm/summary.yaml" | head -1)"

echo "== 3. the same launch twice"
cat > "$WORK/launch.yaml" <<YAML
name: twice
stop_timeout: 5
processes:
  - name: estimator
    command: $BIN/estimator
    args: [--setup, "$WORK/data/setup.yaml", --heartbeat, 0.2]
    required: true
    respawn: on-failure
    respawn_delay: 0.2
YAML
python3 "$SRC/scripts/supervisor.py" "$WORK/launch.yaml" > "$WORK/launch_1.log" 2>&1 &
SUP1=$!; PIDS+=($SUP1)
wait_for "$WORK/launch_1.log" "strategy" 20 "the first launch's estimator did not start"
python3 "$SRC/scripts/supervisor.py" "$WORK/launch.yaml" > "$WORK/launch_2.log" 2>&1 &
SUP2=$!; PIDS+=($SUP2)
wait_exit "$SUP2" "the second launch" 30; rc=$?
(( rc == 1 )) || fail "the second launch exited with $rc, not 1"
grep -q "refused to run" "$WORK/launch_2.log" || fail "the second launch did not say why"
grep -q "restarting estimator" "$WORK/launch_2.log" && fail "the refused estimator was restarted"
kill -0 "$SUP1" 2>/dev/null || fail "the first launch stopped"
grep -q "estimator exited" "$WORK/launch_1.log" && fail "the first launch's estimator exited"
kill -TERM "$SUP1"; wait_exit "$SUP1" "the first launch" 30; rc=$?; (( rc == 0 )) || fail "the first launch exited with $rc"
echo "second launch: exit 1, $(grep -o 'estimator refused to run.*' "$WORK/launch_2.log" | head -1 | cut -c1-90)"
echo "PASS"
