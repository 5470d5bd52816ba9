#!/usr/bin/env bash
# The fly-by system across hosts (issue 12): config/launch/multihost.yaml through
# scripts/multihost_netns.sh, every host (anchor101 ... anchor110, uav, ground) in its own network
# namespace, LCM with ttl=1 through meshnav_netem_switch.
#
#   multihost_test.sh SOURCE_DIR BIN_DIR WORK_DIR MODE
#
# MODE faults: every link loses 20 %, delays 20 ± 10 ms, reorders 5 % and duplicates 2 % of the
#   datagrams; the clocks of anchor107's and anchor109's computers are off by +40 ms and -25 ms
#   (uwb_bridge --clock-offset) and corrected by TIME_SYNC. Replay at 4x. Checks: every host exits
#   0, the mission finishes, anchors 106-110 calibrated within 0.3 m, the logged estimate's
#   position RMSE <= 0.15 m, losses and duplicates counted per channel by the switch, duplicated
#   ranges dropped by the estimator (RANGE:duplicate), the two clock offsets estimated within their own bound (half the smallest round trip, <= 20 ms).
# Every mode: the switch (the network) no more than 100 ms behind its fault model (switch.yaml
#   "behind"; it runs at real-time priority, scripts/multihost_netns.sh). A switch seconds behind
#   delivered ranges 12 s late and a CALIB_CMD after the run on a loaded CI machine: that run
#   tested the machine's load, not meshnav, and now fails saying so.
# MODE kill: clean links, real time; anchors calibrated at 50 s (tests/integration/data/
#   mission_calibrate_50s.yaml); kill -9 of the estimator at t = 60 s; the run is stopped at 75 s.
#   Checks: the supervisor restarts it, POSE again within 2 s, position error <= 0.3 m from 10 s
#   after the kill, the calibrated anchors back from the checkpoint (5 anchors) without a new
#   ANCHOR_INIT.
# MODE kill_calibrator: clean links, 4x, the paper's mission (calibrations at 80 and 100 s); kill -9
#   of the calibrator at t = 60 s while it collects. Checks: it is restarted and replays its input
#   journal (--state-dir), every host exits 0, the mission finishes, anchors 106-110 within 0.3 m.
#
# Skips (exit 77, "SKIP: reason") when network namespaces cannot be created (not root). Waits are
# on conditions (log lines, process exits, wall time of the data), bounded.
set -u
SRC=$(cd "$1" && pwd)
BIN=$(cd "$2" && pwd)
WORK=$3
MODE=$4
ANCHORS=106,107,108,109,110
rm -rf "$WORK"
mkdir -p "$WORK"
MH=""
cleanup() { [[ -n "$MH" ]] && kill -TERM "$MH" 2> /dev/null && wait "$MH"; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$WORK"/logs/uav.log "$WORK"/logs/ground.log "$WORK/multihost.log"; do
    [[ -f "$f" ]] && { echo "---- $f (last lines)"; tail -n 25 "$f"; }
  done
  exit 1
}
now_us() { date +%s%6N; }
(( $(id -u) == 0 )) || { echo "SKIP: network namespaces need root (ip netns add)"; exit 77; }

echo "== simulate seed 1"
"$BIN/meshnav_sim" --seed 1 --out "$WORK/data" > "$WORK/sim.log" 2>&1 || fail "meshnav_sim"
t0=$(sed -n 2p "$WORK/data/imu.csv" | cut -d, -f1)

VARS=(BIN="$BIN" DATASET="$WORK/data" OUT="$WORK/out" MISSION_T0="$t0"
      ESTIMATOR_CONFIG="$SRC/config/estimator.yaml" CALIBRATOR_CONFIG="$SRC/config/calibrator.yaml")
NETEM=""
case "$MODE" in
  faults)
    RATE=4
    NETEM="loss 20% delay 20ms 10ms reorder 5% duplicate 2%"
    VARS+=(RATE=$RATE MISSION="$SRC/config/missions/paper_s2.yaml" CLOCK_OFFSET_107=0.040 CLOCK_OFFSET_109=-0.025) ;;
  kill)
    RATE=1
    VARS+=(RATE=$RATE MISSION="$SRC/tests/integration/data/mission_calibrate_50s.yaml") ;;
  kill_calibrator)
    RATE=4
    VARS+=(RATE=$RATE MISSION="$SRC/config/missions/paper_s2.yaml") ;;
  *) fail "MODE must be faults, kill or kill_calibrator" ;;
esac

echo "== config/launch/multihost.yaml across namespaces, ${RATE}x, netem: ${NETEM:-none}"
cd "$SRC" || fail "cannot cd to $SRC"
bash "$SRC/scripts/multihost_netns.sh" --netem "$NETEM" --logs "$WORK/logs" --timeout 300 \
  "$SRC/config/launch/multihost.yaml" "${VARS[@]}" > "$WORK/multihost.log" 2>&1 &
MH=$!
start=$(now_us)
until grep -q "T0_UTIME" "$WORK/multihost.log"; do
  kill -0 "$MH" 2> /dev/null || break
  (( $(now_us) - start < 30000000 )) || fail "no start line after 30 s"
  sleep 0.05
done
if grep -q "^SKIP:" "$WORK/multihost.log"; then
  grep "^SKIP:" "$WORK/multihost.log"
  exit 77
fi
T0=$(grep -o "T0_UTIME [0-9]*" "$WORK/multihost.log" | awk '{print $2}')
[[ -n "$T0" ]] || fail "multihost_netns.sh did not start: $(tail -n 5 "$WORK/multihost.log")"
grep "^multihost:" "$WORK/multihost.log" | head -n 1

if [[ "$MODE" == kill* ]]; then
  victim=$([[ "$MODE" == kill ]] && echo estimator || echo calibrator)
  # Data time t (the dataset starts at 0) is played at wall time T0 + t / RATE.
  kill_at=$(( T0 + 60000000 / RATE ))
  while (( $(now_us) < kill_at )); do
    kill -0 "$MH" 2> /dev/null || fail "the run ended before t = 60 s"
    sleep 0.02
  done
  pid=$(grep -o "started $victim (pid [0-9]*)" "$WORK/logs/uav.log" | tail -n 1 | grep -o "[0-9]*")
  [[ -n "$pid" ]] || fail "no $victim pid in uav.log"
  kill -9 "$pid" || fail "cannot kill the $victim (pid $pid)"
  killed=$(now_us)
  echo "killed the $victim (pid $pid) at t = $(( (killed - T0) * RATE / 1000 )) ms of data time"
  until grep -q "respawning $victim" "$WORK/logs/uav.log"; do
    (( $(now_us) - killed < 5000000 )) || fail "the supervisor did not restart the $victim within 5 s"
    sleep 0.01
  done
  echo "restarted after $(( ($(now_us) - killed) / 1000 )) ms (supervisor respawn)"
fi
if [[ "$MODE" == kill ]]; then
  stop_at=$(( T0 + 75000000 / RATE ))
  while (( $(now_us) < stop_at )); do
    kill -0 "$MH" 2> /dev/null || fail "the run ended before t = 75 s"
    sleep 0.2
  done
  kill -TERM "$MH"
fi
while kill -0 "$MH" 2> /dev/null; do
  (( $(now_us) - start < 280000000 )) || fail "the run still goes after 280 s"
  sleep 0.2
done
wait "$MH"; rc=$?; MH=""
echo "multihost run finished after $(( ($(now_us) - start) / 1000000 )) s, exit code $rc"
grep "^multihost: host .* finished" "$WORK/multihost.log" | sed 's/^/  /'
OUT="$WORK/out"
LOGS="$WORK/logs"
[[ -s "$LOGS/switch.yaml" ]] || fail "the switch wrote no counters"
sed -n '/^channels:/,$p' "$LOGS/switch.yaml" | sed 's/^/  /'
# The switch's own lag (copies sent after their delivery time because it was not scheduled): a run
# whose network was seconds behind does not test the product (see scripts/multihost_netns.sh).
behind=$(grep "^behind: " "$LOGS/switch.yaml") || fail "no behind: line in switch.yaml"
echo "  switch $behind"
behind_ms=$(sed 's/.*max_ms: \([0-9]*\).*/\1/' <<< "$behind")
# 100 ms of wall time: under the estimator's 1 s window of data time at 4x (250 ms), and five times
# the most the switch fell behind in 12 runs at real-time priority on a loaded machine (20 ms).
(( behind_ms <= 100 )) || fail "the switch fell $behind_ms ms behind its fault model (the machine is overloaded): the run does not test meshnav"
for f in summary.yaml estimate.csv anchors.csv calibration.yaml; do
  [[ -s "$OUT/$f" ]] || fail "no $OUT/$f"
done

if [[ "$MODE" == kill_calibrator ]]; then
  (( rc == 0 )) || fail "a host failed (exit $rc)"
  grep -q "\[mission\].*mission finished" "$LOGS/ground.log" || fail "the mission did not finish"
  grep -q "\[calibrator\].*restart: [0-9]* inputs replayed" "$LOGS/uav.log" \
    || fail "the restarted calibrator did not replay its journal"
  grep "\[calibrator\].*restart:" "$LOGS/uav.log" | cut -c1-220 | sed 's/^/  /'
  "$BIN/meshnav_check_flyby" --truth "$WORK/data/truth.yaml" --anchor-ids $ANCHORS \
    --anchor-init "$OUT/calibration.yaml" --estimate "$OUT/estimate.csv" \
    --groundtruth "$WORK/data/groundtruth.csv" --max-anchor-error 0.3 --max-rmse 0.15 \
    || fail "fly-by results off (see above)"
elif [[ "$MODE" == faults ]]; then
  (( rc == 0 )) || fail "a host failed (exit $rc)"
  grep -q "\[mission\].*mission finished" "$LOGS/ground.log" || fail "the mission did not finish"
  # The switch lost and duplicated datagrams of the channels that cross the links.
  for ch in RANGE IMU POSE; do
    line=$(grep "^  $ch: " "$LOGS/switch.yaml") || fail "no $ch in switch.yaml"
    lost=$(sed 's/.*lost: \([0-9]*\).*/\1/' <<< "$line")
    dup=$(sed 's/.*duplicated: \([0-9]*\).*/\1/' <<< "$line")
    (( lost > 0 && dup > 0 )) || fail "$ch: no loss or duplicate counted ($line)"
  done
  dups=$(grep -o "RANGE:duplicate=[0-9]*" "$LOGS/uav.log" | tail -n 1 | cut -d= -f2)
  (( ${dups:-0} > 0 )) || fail "the estimator counted no duplicated range"
  echo "  estimator: ${dups} duplicated ranges dropped"
  # theta = reference clock - the anchor computer's clock [ms]: anchor107's clock is off by +40 ms
  # (theta -40), anchor109's by -25 ms (theta +25). The bridges log theta's estimate and its bound.
  for a in 107:-40 109:25; do
    id=${a%%:*}; want=${a##*:}
    line=$(grep -o "time sync: offset [-+0-9.]* ms (± [0-9.]* ms)" "$LOGS/anchor$id.log" | tail -n 1)
    got=$(awk '{print $4}' <<< "$line"); bound=$(sed 's/.*(± \([0-9.]*\) ms)/\1/' <<< "$line")
    [[ -n "$got" && -n "$bound" ]] || fail "anchor$id reported no clock offset"
    # The exchange with the smallest round trip bounds the error by half of it (delays are not
    # negative): the estimate must be inside its own bound (0.1 ms for the log's rounding) ...
    awk -v g="$got" -v w="$want" -v b="$bound" 'BEGIN { d = g - w; if (d < 0) d = -d; exit !(d <= b + 0.1) }' \
      || fail "anchor$id: offset estimate $got ms, true theta $want ms (its clock off by $(( -want )) ms): outside its own bound ± $bound ms"
    # ... and that bound tight: 20 ± 10 ms each way gives round trips of 20-60 ms, half of them
    # under 40 ms, so the best of the last 16 exchanges is under 40 ms (bound 20 ms) unless the
    # network held the datagrams longer than --netem says (the switch's "behind" above).
    awk -v b="$bound" 'BEGIN { exit !(b <= 20) }' \
      || fail "anchor$id: offset estimate $got ms (true $want ms) but its bound ± $bound ms > 20 ms: no round trip under 40 ms among the last exchanges"
    echo "  anchor$id: estimated offset $got ms (± $bound ms; true $want ms: its clock is off by $(( -want )) ms)"
  done
  "$BIN/meshnav_check_flyby" --truth "$WORK/data/truth.yaml" --anchor-ids $ANCHORS \
    --anchor-init "$OUT/calibration.yaml" --estimate "$OUT/estimate.csv" \
    --groundtruth "$WORK/data/groundtruth.csv" --max-anchor-error 0.3 --max-rmse 0.15 \
    || fail "fly-by results off (see above)"
else
  grep -q "restart: checkpoint of t = .* with 5 anchors" "$LOGS/uav.log" \
    || fail "the restarted estimator did not resume 5 anchors: $(grep -m1 'restart\|checkpoint' "$LOGS/uav.log")"
  grep "restart: checkpoint" "$LOGS/uav.log" | cut -c1-160 | sed 's/^/  /'
  /usr/bin/python3 "$SRC/tests/integration/pose_gap.py" "$OUT/estimate.csv" "$WORK/data/groundtruth.csv" 60 \
    --until 75 > "$WORK/gap.txt" || fail "pose_gap.py"
  sed 's/^/  /' "$WORK/gap.txt"
  gap=$(awk '$1 == "gap" {print $2}' "$WORK/gap.txt")
  err=$(awk '$1 == "max_error_after" {print $2}' "$WORK/gap.txt")
  awk -v g="$gap" 'BEGIN { exit !(g <= 2.0) }' || fail "no POSE for $gap s around the kill (> 2 s)"
  awk -v e="$err" 'BEGIN { exit !(e <= 0.3) }' || fail "position error $err m from 10 s after the kill (> 0.3 m)"
  n_init=$(grep -o "^  ANCHOR_INIT: {messages: [0-9]*" "$OUT/summary.yaml" | grep -o "[0-9]*$")
  [[ "${n_init:-0}" == 5 ]] || fail "ANCHOR_INIT messages: ${n_init:-0}, expected the 5 of the calibration at 50 s only"
  # The anchors the estimator publishes after the restart are the ones it had before: they barely
  # move (< 5 cm) and keep their covariance (not the setup prior, not a recalibration).
  /usr/bin/python3 "$SRC/tests/integration/pose_gap.py" --anchors "$OUT/anchors.csv" 60 $ANCHORS > "$WORK/anchors.txt" \
    || fail "anchors missing after the restart: $(cat "$WORK/anchors.txt")"
  sed 's/^/  /' "$WORK/anchors.txt"
  awk '{ if (!($4 < 0.05 && $6 < 1.5)) bad = bad " " $2 } END { if (bad) { print bad; exit 1 } }' "$WORK/anchors.txt" \
    || fail "anchors not resumed after the restart (see above)"
fi
echo "PASS"
