#!/bin/sh
# Usage: eval_without_estimate_test.sh BIN_DIR WORK_DIR
# Issue 36: a run whose estimate.csv holds no row (a run stopped before its first pose, a torn
# file) against a dataset with ground truth must not be evaluated as healthy: meshnav_eval exits 1
# and says the pose metrics are missing (it used to print "pose metrics: not available", exit 0).
bin="$1"; work="$2"
rm -rf "$work" && mkdir -p "$work" || exit 1
"$bin/meshnav_sim" --seed 2 --duration 40 --out "$work/data" > "$work/sim.log" 2>&1 || { cat "$work/sim.log"; exit 1; }
"$bin/meshnav_run" --dataset "$work/data" --out "$work/run" --no-calibration > "$work/run.log" 2>&1 || { tail "$work/run.log"; exit 1; }
"$bin/meshnav_eval" --dataset "$work/data" --run "$work/run" --no-plots > "$work/eval_ok.log" 2>&1 || { echo "FAIL: the complete run does not evaluate"; tail "$work/eval_ok.log"; exit 1; }
head -n 1 "$work/run/estimate.csv" > "$work/run/estimate.tmp" && mv "$work/run/estimate.tmp" "$work/run/estimate.csv"
"$bin/meshnav_eval" --dataset "$work/data" --run "$work/run" --no-plots > "$work/eval.log" 2>&1
rc=$?
if [ "$rc" -ne 1 ]; then echo "FAIL: expected exit 1 without an estimate, got $rc"; cat "$work/eval.log"; exit 1; fi
if ! grep -q "pose metrics not available" "$work/eval.log"; then echo "FAIL: no message"; cat "$work/eval.log"; exit 1; fi
echo "ok: exit 1, $(grep 'pose metrics not available' "$work/eval.log" | head -n 1)"
