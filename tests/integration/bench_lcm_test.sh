#!/usr/bin/env bash
# ./meshnav bench lcm's script at 10x on a 42 s flight: it exits 0, the estimator's POSEs answer
# (nearly) every IMU sample after its initialization and every RANGE, and bench_lcm.yaml has the
# latency, rate and CPU sections. Figures are not asserted (the machine is shared; docs/fleet.md).
#   bench_lcm_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -u
SRC=$1; BUILD=$2; WORK=$3
rm -rf "$WORK"
MESHNAV_BUILD_DIR="$BUILD" bash "$SRC/scripts/bench_lcm.sh" --duration-scale 0.3 --rate 10 --out "$WORK" > "$WORK.log" 2>&1 \
  || { cat "$WORK.log"; echo "FAIL: bench_lcm.sh exited $?"; exit 1; }
y="$WORK/bench_lcm.yaml"
[[ -s "$y" ]] || { echo "FAIL: no $y"; exit 1; }
cat "$y"
for key in imu_to_pose range_to_pose ranges_unanswered channels cpu_percent_of_a_core "  estimator:" "  IMU:" "  POSE:"; do
  grep -q "^$key" "$y" || { echo "FAIL: $y has no '$key'"; exit 1; }
done
n_imu=$(sed -n 's/^  IMU: {messages: \([0-9]*\),.*/\1/p' "$y")
n_answered=$(sed -n 's/^imu_to_pose: {n: \([0-9]*\),.*/\1/p' "$y")
n_range=$(sed -n 's/^  RANGE: {messages: \([0-9]*\),.*/\1/p' "$y")
n_range_answered=$(sed -n 's/^range_to_pose: {n: \([0-9]*\),.*/\1/p' "$y")
echo "IMU $n_imu, answered by a POSE $n_answered; RANGE $n_range, answered $n_range_answered"
# The estimator initializes within the first seconds of the 42 s flight; after that every IMU
# sample gets its POSE.
(( n_answered >= n_imu / 2 )) || { echo "FAIL: only $n_answered of $n_imu IMU samples answered by a POSE"; exit 1; }
(( n_range_answered == n_range )) || { echo "FAIL: $n_range_answered of $n_range RANGE answered"; exit 1; }
echo "PASS"
