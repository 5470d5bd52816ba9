#!/bin/sh
# Usage: run_coverage_test.sh BIN_DIR WORK_DIR
# Issue 36, item 2: an IMU file that ends at 70 s of a 141 s flight ended the estimate at 70 s and
# meshnav_run exited 0. A run whose estimate ends more than 1 s before the vehicle's last input
# says where and exits 5; the whole file exits 0.
bin="$1"; work="$2"
rm -rf "$work" && mkdir -p "$work" || exit 1
"$bin/meshnav_sim" --seed 1 --out "$work/data" > "$work/sim.log" 2>&1 || { cat "$work/sim.log"; exit 1; }
"$bin/meshnav_run" --dataset "$work/data" --out "$work/whole" --no-calibration > "$work/whole.log" 2>&1
rc=$?
if [ "$rc" -ne 0 ]; then echo "FAIL: the whole flight, expected exit 0, got $rc"; tail -5 "$work/whole.log"; exit 1; fi
# The IMU file cut at t = 70 s (the header and every row before it).
awk -F, 'NR == 1 || $1 < 70.0' "$work/data/imu.csv" > "$work/imu.csv" && mv "$work/imu.csv" "$work/data/imu.csv" || exit 1
"$bin/meshnav_run" --dataset "$work/data" --out "$work/cut" --no-calibration > "$work/cut.log" 2>&1
rc=$?
if [ "$rc" -ne 5 ]; then echo "FAIL: IMU cut at 70 s, expected exit 5, got $rc"; tail -5 "$work/cut.log"; exit 1; fi
grep -q "the estimate ends at 69.99.* s before the last input at 14" "$work/cut.log" ||
  { echo "FAIL: no message naming the end of the estimate"; tail -5 "$work/cut.log"; exit 1; }
last=$(tail -1 "$work/cut/estimate.csv" | cut -d, -f1)
echo "ok: exit 0 for the whole flight, exit 5 with the IMU cut at 70 s (estimate ends at $last s)"
