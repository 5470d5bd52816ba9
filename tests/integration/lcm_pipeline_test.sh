#!/usr/bin/env bash
# Integration over LCM (docs/channels.md): simulate a sequence, run estimator + logging + imu_bridge +
# uwb_bridge as separate processes over udpm (bridges at 10x, waiting for the estimator's
# heartbeat, in step from a shared t0; malformed messages injected on RANGE and IMU), wait for
# the bridges to finish and the estimate to reach the end of the data, stop estimator and logger
# (SIGTERM: they flush), check that nothing was lost and the malformed messages were counted, then
# run meshnav_run on the same data and require the logged estimate's position RMSE to be within
# 5 % of the deterministic run's.
#
#   lcm_pipeline_test.sh BIN_DIR WORK_DIR [SEED]
#
# Runs in a private network namespace (scripts/lcm_netns.sh: unshare -n, or unshare -rn without
# root) with multicast on its loopback; when namespaces are not permitted it falls back to a unique
# udpm port with ttl=0 on the host and says so. Waits are on conditions (process exit, file
# contents), each bounded. MESHNAV_NO_NETNS=1 forces the fallback.
set -u
BIN=$(cd "$1" && pwd)
WORK=$2
SEED=${3:-3}
RATE=10

# Private network namespace with multicast on its loopback (or the documented fallback).
if [[ -z "${MESHNAV_PIPELINE_INSIDE:-}" ]]; then
  export MESHNAV_PIPELINE_INSIDE=1
  exec bash "$(dirname "$0")/../../scripts/lcm_netns.sh" bash "$0" "$@"
fi

rm -rf "$WORK"
mkdir -p "$WORK"
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill -KILL "$p" 2>/dev/null; done
}
trap cleanup EXIT

fail() {
  echo "FAIL: $*"
  for f in "$WORK"/*.log; do echo "---- $f (last lines)"; tail -n 15 "$f"; done
  exit 1
}

now_us() { date +%s%6N; }

# wait_exit PID NAME SECONDS: waits for the process to exit; echoes its exit code.
wait_exit() {
  local pid=$1 name=$2 limit=$3 start
  start=$(now_us)
  while kill -0 "$pid" 2>/dev/null; do
    if (( $(now_us) - start > limit * 1000000 )); then fail "$name still running after ${limit} s"; fi
    sleep 0.1
  done
  wait "$pid"
}

echo "== simulate seed $SEED"
"$BIN/meshnav_sim" --seed "$SEED" --out "$WORK/data" > "$WORK/sim.log" 2>&1 || fail "meshnav_sim"
last_imu_t=$(tail -n 1 "$WORK/data/imu.csv" | cut -d, -f1)
echo "data ends at t = $last_imu_t s"

echo "== start estimator and logging over $LCM_DEFAULT_URL"
"$BIN/estimator" --setup "$WORK/data/setup.yaml" --heartbeat 0.2 > "$WORK/estimator.log" 2>&1 &
EST=$!; PIDS+=($EST)
"$BIN/logging" --out "$WORK/lcm" --lcmlog "$WORK/lcm/run.lcmlog" --flush-period 0.2 > "$WORK/logging.log" 2>&1 &
LOG=$!; PIDS+=($LOG)

T0=$(( $(now_us) + 2000000 ))
echo "== start both bridges at ${RATE}x, in step from t0 = $T0 us, waiting for ESTIMATOR_STATUS"
for b in imu_bridge uwb_bridge; do
  "$BIN/$b" --dataset "$WORK/data" --rate $RATE --t0-utime $T0 --wait-for ESTIMATOR_STATUS \
    --wait-timeout 30 --progress 2 > "$WORK/$b.log" 2>&1 &
  PIDS+=($!)
done
IMU=${PIDS[2]}; UWB=${PIDS[3]}

# Malformed messages while the system runs: they must be counted, not crash anything, and not
# change the estimate. Injected once the estimator's heartbeat is seen (it has subscribed).
start=$(now_us)
until grep -q "ESTIMATOR_STATUS seen" "$WORK/imu_bridge.log"; do
  (( $(now_us) - start < 30000000 )) || fail "the bridges never saw ESTIMATOR_STATUS"
  sleep 0.05
done
"$BIN/meshnav_publish_garbage" --channel RANGE --count 4 || fail "cannot publish garbage"
"$BIN/meshnav_publish_garbage" --channel IMU --count 2 || fail "cannot publish garbage"

wait_exit "$IMU" imu_bridge 120; rc=$?; (( rc == 0 )) || fail "imu_bridge exited with $rc"
wait_exit "$UWB" uwb_bridge 120; rc=$?; (( rc == 0 )) || fail "uwb_bridge exited with $rc"
echo "bridges done: $(grep -h 'published' "$WORK"/imu_bridge.log "$WORK"/uwb_bridge.log | sed 's/.*info\] //' | tr '\n' ';')"

echo "== wait until the logged estimate reaches the end of the data"
start=$(now_us)
while true; do
  last_est_t=$(tail -n 1 "$WORK/lcm/estimate.csv" 2>/dev/null | cut -d, -f1)
  if [[ "$last_est_t" =~ ^[0-9.]+$ ]] && awk -v a="$last_est_t" -v b="$last_imu_t" 'BEGIN{exit !(a >= b - 0.05)}'; then
    break
  fi
  (( $(now_us) - start < 30000000 )) || fail "estimate.csv stopped at t = ${last_est_t:-none} (< $last_imu_t)"
  sleep 0.1
done
echo "estimate reached t = $last_est_t s"

kill -TERM "$EST"; wait_exit "$EST" estimator 20; rc=$?; (( rc == 0 )) || fail "estimator exited with $rc on SIGTERM"
kill -TERM "$LOG"; wait_exit "$LOG" logging 20; rc=$?; (( rc == 0 )) || fail "logging exited with $rc on SIGTERM"
[[ -s "$WORK/lcm/summary.yaml" ]] || fail "logging wrote no summary.yaml"
[[ -s "$WORK/lcm/run.lcmlog" ]] || fail "logging wrote no run.lcmlog"
grep -q "RANGE:decode_error: 4" "$WORK/lcm/summary.yaml" || fail "the estimator did not count 4 malformed RANGE messages"
grep -q "IMU:decode_error: 2" "$WORK/lcm/summary.yaml" || fail "the estimator did not count 2 malformed IMU messages"
grep -E "^  (IMU|RANGE|POSE):" "$WORK/lcm/summary.yaml"
# Nothing lost on the way: the logger received every message the bridges published (plus the
# injected malformed ones).
n_imu=$(( $(sed -n 's/.*published IMU \([0-9]*\).*/\1/p' "$WORK/imu_bridge.log") + 2 ))
n_range=$(( $(sed -n 's/.*published RANGE \([0-9]*\).*/\1/p' "$WORK/uwb_bridge.log") + 4 ))
grep -q "^  IMU: {messages: $n_imu," "$WORK/lcm/summary.yaml" || fail "logger did not receive all $n_imu IMU messages"
grep -q "^  RANGE: {messages: $n_range," "$WORK/lcm/summary.yaml" || fail "logger did not receive all $n_range RANGE messages"
grep -q "initialized: true" "$WORK/lcm/summary.yaml" || fail "the estimator never initialized"

echo "== deterministic run (meshnav_run, estimator only like the launched processes) on the same data"
"$BIN/meshnav_run" --dataset "$WORK/data" --out "$WORK/run" --no-calibration > "$WORK/run.log" 2>&1 || fail "meshnav_run"

echo "== compare position RMSE against ground truth"
"$BIN/meshnav_compare_estimates" --groundtruth "$WORK/data/groundtruth.csv" --reference "$WORK/run/estimate.csv" \
  --candidate "$WORK/lcm/estimate.csv" --tolerance 0.05 || fail "LCM pipeline RMSE not within 5 % of meshnav_run"

echo "== the fixed-lag smoother (POSE_SMOOTHED): one per POSE, as meshnav_run's, better than the filter"
[[ -s "$WORK/lcm/estimate_smoothed.csv" ]] || fail "logging wrote no estimate_smoothed.csv (no POSE_SMOOTHED)"
n_pose=$(sed -n 's/^  POSE: {messages: \([0-9]*\),.*/\1/p' "$WORK/lcm/summary.yaml")
n_smoothed=$(sed -n 's/^  POSE_SMOOTHED: {messages: \([0-9]*\),.*/\1/p' "$WORK/lcm/summary.yaml")
echo "POSE $n_pose, POSE_SMOOTHED $n_smoothed"
[[ -n "$n_pose" && "$n_pose" == "$n_smoothed" ]] || fail "POSE_SMOOTHED ($n_smoothed) is not one per POSE ($n_pose)"
"$BIN/meshnav_compare_estimates" --groundtruth "$WORK/data/groundtruth.csv" --reference "$WORK/run/estimate_smoothed.csv" \
  --candidate "$WORK/lcm/estimate_smoothed.csv" --tolerance 0.05 || fail "POSE_SMOOTHED RMSE not within 5 % of meshnav_run's"
"$BIN/meshnav_compare_estimates" --groundtruth "$WORK/data/groundtruth.csv" --reference "$WORK/lcm/estimate.csv" \
  --candidate "$WORK/lcm/estimate_smoothed.csv" --tolerance 10 > "$WORK/smoothed_vs_filter.txt" 2>&1 || true
cat "$WORK/smoothed_vs_filter.txt"
rmse_filter=$(sed -n 's/^reference: .*RMSE \([0-9.]*\) m/\1/p' "$WORK/smoothed_vs_filter.txt")
rmse_smoothed=$(sed -n 's/^candidate: .*RMSE \([0-9.]*\) m/\1/p' "$WORK/smoothed_vs_filter.txt")
awk -v f="$rmse_filter" -v s="$rmse_smoothed" 'BEGIN { exit !(f != "" && s != "" && s + 0 < f + 0) }' || fail "the smoothed poses are not better than the filter's"
echo "PASS"
