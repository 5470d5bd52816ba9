#!/usr/bin/env bash
# The logger's --lcmlog on a full disk (issue 36 item 1): every event lost is named and the logger
# exits 1; before, the write errors were counted and it exited 0. The real `logging` process and
# meshnav_publish_sequence over udpm in a private network namespace; --lcmlog /dev/full fails
# every write with ENOSPC. The CSVs and summary.yaml (another folder) are still whole.
#   logger_write_error_test.sh BIN_DIR WORK_DIR
set -u
BIN=$(cd "$1" && pwd)
WORK=$2
SRC=$(cd "$(dirname "$0")/../.." && pwd)
if [[ -z "${MESHNAV_LOGGER_FULL_INSIDE:-}" ]]; then
  export MESHNAV_LOGGER_FULL_INSIDE=1
  exec bash "$SRC/scripts/lcm_netns.sh" bash "$0" "$@"
fi
rm -rf "$WORK"
mkdir -p "$WORK"
fail() { echo "FAIL: $*"; tail -n 20 "$WORK/logging.log"; exit 1; }
now_us() { date +%s%6N; }
"$BIN/logging" --out "$WORK/lcm" --lcmlog /dev/full --flush-period 0.2 > "$WORK/logging.log" 2>&1 &
LOG=$!
trap 'kill -KILL $LOG 2>/dev/null' EXIT
start=$(now_us)
until grep -q "recording into" "$WORK/logging.log"; do
  (( $(now_us) - start < 20000000 )) || fail "the logger did not start"
  sleep 0.05
done
"$BIN/meshnav_publish_sequence" --first 0 --count 200 --rate 1000 --record "$WORK/sent.csv" > "$WORK/publish.log" 2>&1 \
  || fail "meshnav_publish_sequence failed"
start=$(now_us)
until [[ $(( $(wc -l < "$WORK/lcm/estimate.csv" 2>/dev/null || echo 1) - 1 )) -ge 200 ]]; do
  (( $(now_us) - start < 20000000 )) || fail "estimate.csv did not reach 200 rows"
  sleep 0.05
done
kill -TERM $LOG
wait $LOG; rc=$?
(( rc == 1 )) || fail "the logger exited with $rc on a full --lcmlog, not 1"
grep -q "/dev/full: write failed (No space left on device; [0-9]* of [0-9]* events, [0-9]* bytes, written since the last flush that succeeded are lost or torn)" \
  "$WORK/logging.log" || fail "no message naming /dev/full and the events lost"
[[ -s "$WORK/lcm/summary.yaml" ]] || fail "summary.yaml was not written"
grep -q "lcmlog:write_error" "$WORK/lcm/summary.yaml" || fail "summary.yaml does not count the write errors"
echo "ok: exit 1, $(grep -o '/dev/full: write failed.*torn)' "$WORK/logging.log" | head -1)"
echo "PASS"
