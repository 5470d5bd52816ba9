#!/bin/sh
# Usage: eval_write_error_test.sh BIN_DIR WORK_DIR
# Issue 36, item 1: files written once (here meshnav_eval's metrics.yaml) go through a temporary
# renamed over them. With the temporary on a full disk (a link to /dev/full: ENOSPC on every
# write) the tool exits non-zero naming the file, and the metrics.yaml of the run before stays
# whole instead of being left empty or torn.
bin="$1"; work="$2"
rm -rf "$work" && mkdir -p "$work" || exit 1
"$bin/meshnav_sim" --seed 1 --duration 40 --out "$work/data" > "$work/sim.log" 2>&1 || { cat "$work/sim.log"; exit 1; }
"$bin/meshnav_run" --dataset "$work/data" --out "$work/run" --no-calibration > "$work/run.log" 2>&1 || { tail -5 "$work/run.log"; exit 1; }
"$bin/meshnav_eval" --dataset "$work/data" --run "$work/run" --no-plots > "$work/eval1.log" 2>&1 || { tail -5 "$work/eval1.log"; exit 1; }
cp "$work/run/metrics.yaml" "$work/metrics.before" || exit 1
ln -s /dev/full "$work/run/metrics.yaml.tmp" || exit 1
"$bin/meshnav_eval" --dataset "$work/data" --run "$work/run" --no-plots > "$work/eval2.log" 2>&1
rc=$?
if [ "$rc" -eq 0 ]; then echo "FAIL: exit 0 with metrics.yaml on a full disk"; tail -5 "$work/eval2.log"; exit 1; fi
grep -q "metrics.yaml: write failed (No space left on device; nothing written)" "$work/eval2.log" ||
  { echo "FAIL: no message naming metrics.yaml"; tail -5 "$work/eval2.log"; exit 1; }
cmp -s "$work/metrics.before" "$work/run/metrics.yaml" || { echo "FAIL: the earlier metrics.yaml changed"; exit 1; }
[ -e "$work/run/metrics.yaml.tmp" ] && { echo "FAIL: the temporary is left"; exit 1; }
echo "ok: exit $rc naming metrics.yaml, the earlier file whole"
