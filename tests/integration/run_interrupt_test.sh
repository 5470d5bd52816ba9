#!/bin/sh
# Usage: run_interrupt_test.sh BIN_DIR WORK_DIR
# Issue 36: SIGINT (or SIGTERM) to meshnav_run left a torn last row in estimate.csv and an empty
# anchors.csv and status. Now the run stops feeding, writes its rows and end-of-run files, marks
# status.txt `complete: false` and exits 128 + the signal. The signal is sent once the run reports
# 25 % progress (waited for, not slept).
bin="$1"; work="$2"
rm -rf "$work" && mkdir -p "$work" || exit 1
"$bin/meshnav_sim" --seed 3 --duration-scale 4 --out "$work/data" > "$work/sim.log" 2>&1 || { cat "$work/sim.log"; exit 1; }
"$bin/meshnav_run" --dataset "$work/data" --out "$work/run" --no-calibration > "$work/run.log" 2>&1 &
pid=$!
i=0
until grep -q "progress  25%" "$work/run.log"; do
  i=$((i + 1))
  if [ "$i" -gt 1200 ] || ! kill -0 "$pid" 2>/dev/null; then echo "FAIL: no 25 % progress line"; cat "$work/run.log"; exit 1; fi
  sleep 0.05
done
kill -INT "$pid"
wait "$pid"; rc=$?
if grep -q "progress 100%" "$work/run.log"; then echo "SKIP-LIKE FAIL: the run finished before the signal"; exit 1; fi
if [ "$rc" -ne 130 ]; then echo "FAIL: expected exit 130 after SIGINT, got $rc"; tail -5 "$work/run.log"; exit 1; fi
grep -q "interrupted by signal 2" "$work/run.log" || { echo "FAIL: no message"; tail -5 "$work/run.log"; exit 1; }
grep -q "^complete: false" "$work/run/status.txt" || { echo "FAIL: status.txt not marked incomplete"; head -3 "$work/run/status.txt"; exit 1; }
# Every row of estimate.csv whole (as many fields as the header), and some rows; anchors.csv too.
awk -F, 'NR == 1 { n = NF; next } NF != n { bad = 1 } END { if (bad || NR < 100) exit 1 }' "$work/run/estimate.csv" ||
  { echo "FAIL: torn or empty estimate.csv"; tail -2 "$work/run/estimate.csv"; exit 1; }
[ "$(wc -l < "$work/run/anchors.csv")" -gt 1 ] || { echo "FAIL: empty anchors.csv"; exit 1; }
"$bin/meshnav_eval" --dataset "$work/data" --run "$work/run" --no-plots > "$work/eval.log" 2>&1 ||
  { echo "FAIL: the interrupted run's rows do not evaluate"; tail -5 "$work/eval.log"; exit 1; }
echo "ok: exit 130, $(wc -l < "$work/run/estimate.csv") estimate rows, status complete: false"
