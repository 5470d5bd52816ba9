#!/usr/bin/env bash
# A fleet's inter-vehicle ranges over LCM (docs/fleet.md, "Inter-vehicle ranges over LCM"): two
# vehicles of a short scaled fleet (meshnav_sim --vehicles 2) whose anchors do not answer v0 for
# 15 s (--outage), run twice by the launch of `meshnav_fleet_launch` under scripts/supervisor.py
# in a private network namespace, each vehicle on its own bus: with the fleet's peer_router (the
# default) and with --no-peer-router. Asserts that
#  - both launches exit 0; the first ran `fleet_peer_router`, the second not;
#  - with it, v0's logger recorded PEER_RANGE on v0/PEER_RANGE (the vehicle short of anchors
#    receives), v0's estimator fused at least half of them (its counter peer_range_fused), v1
#    (which had its anchors) received few (at most a tenth of v0's);
#  - over the outage v0's position error with the peer_router is at most half of that without it
#    (RMSE), at most 0.5 m, and at most 0.1 m above that of the same fleet in one process
#    (meshnav_run --fleet): the peer's ranges hold it as they do there;
#  - outside the outage both vehicles follow the truth with the peer_router (RMSE < 0.3 m), and v1
#    without it (v0, lost in the outage, is not held to it then);
#  - a restart drill in the run with the peer_router: once its journal says that v0 holds v1's
#    information (--state-dir, pipeline/peer_router_state.h), the router is killed (-9) in the
#    outage; the supervisor respawns it, the respawn takes the journal back (its counter
#    peer_router_state_restored > 0) and routes again (the outage checks above hold across it).
#   fleet_peer_ranges_lcm_test.sh SOURCE_DIR BIN_DIR WORK_DIR
set -u
SRC=$1; BIN=$2; WORK=$3
if [[ -z "${MESHNAV_FLEET_PEER_TEST_INSIDE:-}" ]]; then
  rm -rf "$WORK"; mkdir -p "$WORK"
  export MESHNAV_FLEET_PEER_TEST_INSIDE=1
  exec bash "$SRC/scripts/lcm_netns.sh" bash "$0" "$@"
fi
SUP=""
cleanup() { [[ -n "$SUP" ]] && kill -TERM "$SUP" 2>/dev/null; wait 2>/dev/null; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; for f in "$WORK"/*.log; do echo "---- $f"; tail -n 25 "$f"; done; exit 1; }
cd "$SRC" || fail "no $SRC"
T0=15; T1=30
"$BIN/meshnav_sim" --vehicles 2 --anchors 16 --hall 12,12,6 --duration 40 --seed 3 --outage "0,$T0,$T1" \
  --out "$WORK/data" > "$WORK/sim.log" 2>&1 || fail "meshnav_sim --vehicles 2 --outage failed"
"$BIN/meshnav_run" --fleet "$WORK/data/fleet.yaml" --no-calibration --allow-lost --config "$SRC/config/fleet_scale.yaml" \
  --out "$WORK/one_process" > "$WORK/one_process.log" 2>&1 || fail "meshnav_run --fleet failed"
for mode in with without; do
  extra=()
  [[ $mode == without ]] && extra=(--no-peer-router)
  "$BIN/meshnav_fleet_launch" --fleet "$WORK/data/fleet.yaml" --out "$WORK/launch_$mode.yaml" \
    --estimator-config "$SRC/config/fleet_scale.yaml" "${extra[@]}" > "$WORK/fleet_launch_$mode.log" 2>&1 \
    || fail "meshnav_fleet_launch ($mode) failed"
  python3 "$SRC/scripts/supervisor.py" "$WORK/launch_$mode.yaml" BIN="$BIN" OUT="$WORK/run_$mode" RATE=2 \
    > "$WORK/supervisor_$mode.log" 2>&1 &
  SUP=$!
  if [[ $mode == with ]]; then
    # The drill: wait (bounded) for a journal in which v0 holds v1's information, then kill -9.
    killed=""
    for _ in $(seq 1 600); do
      j=$(ls "$WORK"/run_with/fleet_peer_router_state/*/peer_router_state.yaml 2>/dev/null | head -1)
      if [[ -n "$j" ]] && grep -q "^  v0: {v1:" "$j"; then
        pkill -9 -f "peer_router --fleet $WORK/data/fleet.yaml" && killed=yes
        break
      fi
      kill -0 "$SUP" 2>/dev/null || break
      sleep 0.1
    done
    [[ -n "$killed" ]] || fail "no journal with v0 holding v1's information, or no peer_router to kill"
  fi
  wait "$SUP"; rc=$?; SUP=""
  (( rc == 0 )) || fail "the fleet launch ($mode peer_router) exited with $rc"
done
grep -q "^\[supervisor\] started fleet_peer_router " "$WORK/supervisor_with.log" || fail "no fleet_peer_router started"
grep -q "^\[supervisor\] started fleet_peer_router " "$WORK/supervisor_without.log" \
  && fail "--no-peer-router started a fleet_peer_router"
grep "\[fleet_peer_router\].*stopped:" "$WORK/supervisor_with.log" | tail -1
grep -q "^\[supervisor\] respawning fleet_peer_router" "$WORK/supervisor_with.log" || fail "the killed peer_router was not respawned"
grep -q "\[fleet_peer_router\].*restart: provenance journal" "$WORK/supervisor_with.log" \
  || fail "the respawned peer_router did not find its journal"
grep "\[fleet_peer_router\].*stopped:" "$WORK/supervisor_with.log" | tail -1 | grep -Eq "peer_router_state_restored[=: ]+[1-9]" \
  || fail "the respawned peer_router did not take its journal back (peer_router_state_restored)"
grep "\[fleet_peer_router\].*stopped:" "$WORK/supervisor_with.log" | tail -1 | grep -Eq "stopped: [1-9][0-9]* PEER_RANGE sent" \
  || fail "the respawned peer_router routed nothing"
python3 "$SRC/tests/integration/fleet_peer_ranges_check.py" "$WORK" "$T0" "$T1" || fail "see above"
echo "PASS"
