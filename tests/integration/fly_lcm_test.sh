#!/usr/bin/env bash
# The closed loop over LCM (docs/closed_loop.md "Over LCM"): scripts/fly_lcm.sh runs vehicle_sim,
# estimator, calibrator, mission, controller and logging (config/launch/fly.yaml) in a private
# network namespace and flies the short mission tests/integration/data/short_closed_loop.yaml.
# Waits are on conditions (the launch's exit; the drill waits for the vehicle's progress line).
#   fly_lcm_test.sh SOURCE_DIR BIN_DIR WORK_DIR MODE
# MODE
#   lockstep        lock-step: lands within 0.3 m, estimation RMSE <= 0.15 m, tracking <= 0.25 m,
#                   both anchors calibrated fly-by, no failsafe; the logger recorded CONTROL_CMD and
#                   CONTROL_STATUS; every awaited command came (at most 5 late of ~13 500); 3
#                   malformed CONTROL_CMD and 2 CONTROL_STATUS published at t = 20 s are counted by
#                   vehicle_sim and change nothing.
#   kill_estimator  real time: kill -9 of the estimator at t = 35 s (about 2 m up); the supervisor
#                   respawns it; CONTROL_STATUS shows the failsafe (POSE late) and the flight back;
#                   no crash, the mission completed, landing within 0.5 m.
#   anchor_off      lock-step, anchor 101 off from 20 s: no crash, landing within 0.5 m, its ranges gone.
#   range_loss      lock-step, 20 % of RANGE lost: no crash, landing within 0.5 m.
# lockstep and kill_estimator also play the logger's run.lcmlog into view_server (when built): its
# CONTROL_STATUS row shows the landing, and the drill's failsafe (POSE late).
set -u
SRC=$(cd "$1" && pwd)
BIN=$(cd "$2" && pwd)
WORK=$3
MODE=$4
OUT="$WORK/$MODE"
fail() { echo "FAIL: $*"; [[ -f "$OUT/launch.log" ]] && { echo "---- launch.log (last lines)"; tail -n 30 "$OUT/launch.log"; }; exit 1; }
args=(--out "$OUT" --seed 1 --mission "$SRC/tests/integration/data/short_closed_loop.yaml")
max_landed=0.5
case "$MODE" in
  lockstep) max_landed=0.3 ;;
  kill_estimator) args+=(--realtime --kill-estimator-at 35) ;;
  anchor_off) args+=(--anchor-off 101 --anchor-off-at 20) ;;
  range_loss) args+=(--range-loss 0.2) ;;
  *) fail "unknown MODE $MODE" ;;
esac
# In a network namespace of its own (fly_lcm.sh then stays in it), so that the test can publish
# on the flight's bus.
if [[ -z "${MESHNAV_FLY_LCM_INSIDE:-}" ]]; then
  export MESHNAV_FLY_LCM_INSIDE=1
  exec bash "$SRC/scripts/lcm_netns.sh" bash "$0" "$@"
fi
rm -rf "$OUT"  # a previous run's launch.log would satisfy the waits below at once
mkdir -p "$WORK"
GARBAGE=""
if [[ "$MODE" == lockstep ]]; then
  # Malformed CONTROL_CMD and CONTROL_STATUS once the vehicle flies: counted, the flight goes on.
  (
    for i in $(seq 1 1200); do
      grep -q "\[vehicle_sim\].* t = 20 s (" "$OUT/launch.log" 2>/dev/null && break
      sleep 0.05
    done
    "$BIN/meshnav_publish_garbage" --channel CONTROL_CMD --count 3 &&
      "$BIN/meshnav_publish_garbage" --channel CONTROL_STATUS --count 2
  ) > "$WORK/garbage.out" 2>&1 &
  GARBAGE=$!
fi
MESHNAV_BUILD_DIR="$(dirname "$BIN")" bash "$SRC/scripts/fly_lcm.sh" "${args[@]}"
rc=$?
[[ -n "$GARBAGE" ]] && { wait "$GARBAGE" || fail "meshnav_publish_garbage failed: $(cat "$WORK/garbage.out")"; }
Y="$OUT/closed_loop.yaml"
[[ -s "$Y" ]] || fail "no closed_loop.yaml (fly_lcm.sh exit $rc)"
cat "$Y" | grep -v "^#" | sed 's/^/  /'
(( rc == 0 )) || fail "fly_lcm.sh exited with $rc"
val() { sed -n "s/^$1: \(.*\)$/\1/p" "$Y"; }
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a <= b) }'; }
[[ "$(val over_lcm)" == true ]] || fail "closed_loop.yaml is not of a flight over LCM"
[[ "$(val crashed)" == false ]] || fail "crashed: $(val crash_reason)"
[[ "$(val landed)" == true ]] || fail "not landed"
[[ "$(val mission_complete)" == true ]] || fail "the mission was not completed"
w=$(val landed_within_m)
le 0 "$w" && le "$w" "$max_landed" || fail "landed $w m from the pad (limit $max_landed m)"
grep -q "^  CONTROL_STATUS: {messages:" "$OUT/log/summary.yaml" || fail "the logger saw no CONTROL_STATUS"
grep -q "^  CONTROL_CMD: {messages:" "$OUT/log/summary.yaml" || fail "the logger saw no CONTROL_CMD"
grep -q "^  GROUND_TRUTH: {messages:" "$OUT/log/summary.yaml" || fail "the logger saw no GROUND_TRUTH"
case "$MODE" in
  lockstep)
    le "$(val estimation_rmse_m)" 0.15 || fail "estimation RMSE $(val estimation_rmse_m) m > 0.15 m"
    le "$(val tracking_rmse_m)" 0.25 || fail "tracking RMSE $(val tracking_rmse_m) m > 0.25 m"
    [[ "$(val failsafe_events)" == 0 ]] || fail "failsafe events: $(val failsafe_events)"
    (( $(val commands_late) <= 5 )) || fail "$(val commands_late) commands late"
    stopped=$(grep "\[vehicle_sim\].* stopped at t = " "$OUT/launch.log")
    [[ "$stopped" == *"CONTROL_CMD:decode_error=3"* ]] || fail "vehicle_sim did not count 3 malformed CONTROL_CMD: $stopped"
    [[ "$stopped" == *"CONTROL_STATUS:decode_error=2"* ]] || fail "vehicle_sim did not count 2 malformed CONTROL_STATUS: $stopped"
    for a in 106 107; do
      grep -qE "^  - \{id: $a, initial_error_m: 0\.[0-9]+, final_error_m: 0\.[0-9]+\}" "$Y" || fail "anchor $a not calibrated and fused"
    done
    ;;
  kill_estimator)
    n=$(grep -c "^\[supervisor\] started estimator" "$OUT/launch.log")
    (( n == 2 )) || fail "the estimator was started $n times (expected: once and one respawn)"
    grep -q "killed the estimator" "$OUT/drill.log" || fail "no kill in drill.log"
    grep -qE "\[vehicle_sim\].*CONTROL_STATUS t = [0-9.]+ s: flying -> failsafe \(POSE late\), failsafe events 1" \
      "$OUT/launch.log" || fail "CONTROL_STATUS showed no failsafe for POSE late"
    grep -qE "\[vehicle_sim\].*CONTROL_STATUS t = [0-9.]+ s: failsafe -> flying" "$OUT/launch.log" ||
      fail "CONTROL_STATUS showed no recovery from the failsafe"
    grep -E "\[vehicle_sim\].*CONTROL_STATUS" "$OUT/launch.log" | cut -c1-200 | sed 's/^/  /'
    ;;
  anchor_off)
    grep -qE "\[vehicle_sim\].*faults: anchor 101 off from 20 s \(0 IMU dropped, [1-9][0-9]* ranges of the anchor off" \
      "$OUT/launch.log" || fail "no ranges of anchor 101 were taken away"
    ;;
  range_loss)
    grep -qE "\[vehicle_sim\].*faults: 20 % RANGE loss from 0 s \(0 IMU dropped, 0 ranges of the anchor off, [1-9][0-9]* ranges lost" \
      "$OUT/launch.log" || fail "no ranges were lost"
    ;;
esac
# The live view (view_server, docs/view.md) plays the flight's log: its CONTROL_STATUS row shows how
# the flight ended (the failsafe of the drill included).
if [[ -x "$BIN/view_server" && ( "$MODE" == lockstep || "$MODE" == kill_estimator ) ]]; then
  want='landed (mission complete)'
  [[ "$MODE" == kill_estimator ]] && want='1 (last: POSE late)'
  "$BIN/view_server" --log "$OUT/log/run.lcmlog" --speed 0 --port 0 > "$OUT/view.out" 2> "$OUT/view.err" &
  VIEW=$!
  for i in $(seq 1 600); do
    grep -q "to its end" "$OUT/view.out" 2>/dev/null && break
    kill -0 "$VIEW" 2>/dev/null || fail "view_server exited early: $(tail -n 3 "$OUT/view.err")"
    sleep 0.1
  done
  grep -q "to its end" "$OUT/view.out" || { kill "$VIEW"; fail "the view did not play the log within 60 s"; }
  URL=$(sed -n 's/^view: \(http[^ ]*\)$/\1/p' "$OUT/view.out" | head -n 1)
  python3 - "${URL}api/state" "$want" <<'PY' || { kill "$VIEW"; fail "the view shows no CONTROL_STATUS row with '$want'"; }
import json, sys, urllib.request
j = json.loads(urllib.request.urlopen(sys.argv[1]).read())
rows = [s for s in j["statuses"] if "CONTROL_STATUS" in json.dumps(s)]
print("  view:", json.dumps(rows)[:300])
sys.exit(0 if rows and sys.argv[2] in json.dumps(rows, ensure_ascii=False) else 1)
PY
  kill "$VIEW"; wait "$VIEW"
fi
echo "PASS"
