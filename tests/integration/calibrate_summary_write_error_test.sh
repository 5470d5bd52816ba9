#!/bin/sh
# Usage: calibrate_summary_write_error_test.sh BIN_DIR WORK_DIR
# Issue 36, item 1: meshnav_calibrate appended its --summary-csv lines without checking the stream
# (`if (summary)` skipped the rows once a write had failed) and exited 0. On a full disk (here
# /dev/full: ENOSPC on every write) it now exits non-zero naming the file; the results YAML, written
# once, is not replaced.
bin="$1"; work="$2"
rm -rf "$work" && mkdir -p "$work" || exit 1
"$bin/meshnav_sim" --seed 1 --duration 60 --out "$work/data" > "$work/sim.log" 2>&1 || { cat "$work/sim.log"; exit 1; }
"$bin/meshnav_calibrate" --dataset "$work/data" --anchors 106 --out "$work/ok.yaml" --summary-csv "$work/summary.csv" \
  > "$work/ok.log" 2>&1 || { echo "FAIL: the clean run"; tail -5 "$work/ok.log"; exit 1; }
[ "$(wc -l < "$work/summary.csv")" -eq 2 ] || { echo "FAIL: expected a header and one row"; cat "$work/summary.csv"; exit 1; }
"$bin/meshnav_calibrate" --dataset "$work/data" --anchors 106 --out "$work/full.yaml" --summary-csv /dev/full \
  > "$work/full.log" 2>&1
rc=$?
if [ "$rc" -eq 0 ]; then echo "FAIL: exit 0 with the summary on a full disk"; tail -5 "$work/full.log"; exit 1; fi
grep -q "/dev/full: write failed (No space left on device" "$work/full.log" ||
  { echo "FAIL: no message naming the summary file"; tail -5 "$work/full.log"; exit 1; }
echo "ok: exit $rc naming the summary file"
