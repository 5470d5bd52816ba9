#!/usr/bin/env bash
# One calibrator serving a fleet over LCM (docs/fleet.md, "The fleet's calibrator over LCM"): two
# vehicles of a short scaled fleet (meshnav_sim --vehicles 2, fly-by anchors among 16) run by the
# launch of `meshnav_fleet_launch --fleet-calibrator --mission` under scripts/supervisor.py in a
# private network namespace, each vehicle on its own bus. The calibrator is killed (SIGKILL) once
# it has published its first ANCHOR_INIT and respawned by the supervisor. Asserts that
#  - the launch exits 0; one calibrator (`calibrator --fleet`) and the fleet's mission ran;
#  - every fly-by anchor of the hall (anchors_layout.csv, known 0) reached BOTH vehicles
#    (each one's logger: anchor_init.yaml from its own <vehicle>/ANCHOR_INIT) exactly once, within
#    0.3 m of its true position, and each vehicle's estimator joined it (anchors.csv);
#  - each vehicle's ANCHOR_INIT carries pair biases of its own tags and none of the other's
#    (restrictToVehicle over LCM), and between them both vehicles' tags are references: one
#    calibration from both vehicles' ranges;
#  - the respawned calibrator replayed its journal (--state-dir) and calibrated nothing twice;
#  - the mission's `remove` of one fly-by anchor at 33 s reaches every vehicle's estimator (the
#    fleet's mission sends ESTIMATOR_CMD on each vehicle's bus): its ANCHORS stop listing it;
#  - each vehicle's estimate.csv follows its own truth (RMSE < 0.5 m);
#  - a stop between a calibration and its publication: the run's journal without v1's ANCHOR_INIT
#    records, replayed by a new `calibrator --fleet --state-dir`, makes it send exactly v1's three
#    again (logged "sent now", journaled as sent) and none of v0's, which the journal shows as sent.
#   fleet_calibrator_lcm_test.sh SOURCE_DIR BIN_DIR WORK_DIR
set -u
SRC=$1; BIN=$2; WORK=$3
if [[ -z "${MESHNAV_FLEET_CALIB_TEST_INSIDE:-}" ]]; then
  rm -rf "$WORK"; mkdir -p "$WORK"
  export MESHNAV_FLEET_CALIB_TEST_INSIDE=1
  exec bash "$SRC/scripts/lcm_netns.sh" bash "$0" "$@"
fi
SUP=""
cleanup() { [[ -n "$SUP" ]] && kill -TERM "$SUP" 2>/dev/null; wait 2>/dev/null; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; for f in "$WORK"/*.log; do echo "---- $f"; tail -n 25 "$f"; done; exit 1; }
cd "$SRC" || fail "no $SRC"
"$BIN/meshnav_sim" --vehicles 2 --anchors 16 --hall 12,12,6 --duration 40 --seed 3 --out "$WORK/data" \
  > "$WORK/sim.log" 2>&1 || fail "meshnav_sim --vehicles 2 failed"
# The generated mission and a `remove` of the first fly-by anchor at 33 s: its ESTIMATOR_CMD must
# reach every vehicle (mission --fleet), as in one process.
removed=$(awk -F, 'NR > 1 && $9 == 0 { print $1; exit }' "$WORK/data/anchors_layout.csv")
[[ -n "$removed" ]] || fail "no fly-by anchor in $WORK/data/anchors_layout.csv"
{ cat "$WORK/data/mission.yaml"; echo "  - {t: 33, action: remove, anchors: [$removed]}"; } > "$WORK/mission.yaml"
"$BIN/meshnav_fleet_launch" --fleet "$WORK/data/fleet.yaml" --out "$WORK/launch.yaml" \
  --estimator-config "$SRC/config/fleet_scale.yaml" --fleet-calibrator --mission "$WORK/mission.yaml" \
  --calibrator-config "$SRC/config/calibrator.yaml" > "$WORK/fleet_launch.log" 2>&1 || fail "meshnav_fleet_launch failed"
python3 "$SRC/scripts/supervisor.py" "$WORK/launch.yaml" BIN="$BIN" OUT="$WORK/run" RATE=3 > "$WORK/supervisor.log" 2>&1 &
SUP=$!
# Wait for the first ANCHOR_INIT (a condition, with a deadline), then kill the calibrator hard.
pid=""
for _ in $(seq 600); do
  if grep -q "\[fleet_calibrator\].*ANCHOR_INIT" "$WORK/supervisor.log"; then
    pid=$(sed -n 's/^\[supervisor\] started fleet_calibrator (pid \([0-9]*\)).*/\1/p' "$WORK/supervisor.log" | head -1)
    break
  fi
  kill -0 "$SUP" 2>/dev/null || break
  sleep 0.1
done
[[ -n "$pid" ]] || fail "no ANCHOR_INIT from the fleet calibrator within 60 s"
kill -KILL "$pid" || fail "cannot kill the calibrator ($pid)"
echo "killed the fleet calibrator (pid $pid) after its first ANCHOR_INIT"
wait "$SUP"; rc=$?; SUP=""
(( rc == 0 )) || fail "the fleet launch exited with $rc"
grep -c "^\[supervisor\] started fleet_calibrator " "$WORK/supervisor.log" | grep -qx 2 \
  || fail "the calibrator was not respawned once"
grep -q "^\[supervisor\] started fleet_mission " "$WORK/supervisor.log" || fail "the fleet's mission was not started"
grep -q "\[fleet_calibrator\].*restart: [0-9]* inputs replayed" "$WORK/supervisor.log" \
  || fail "the respawned calibrator did not replay its journal"
python3 - "$WORK" "$removed" <<'PY' || fail "see above"
import bisect, csv, math, os, sys, yaml
work, removed = sys.argv[1], int(sys.argv[2])
data = os.path.join(work, "data")
layout = {int(r["id"]): r for r in csv.DictReader(open(os.path.join(data, "anchors_layout.csv")))}
flyby = sorted(i for i, r in layout.items() if r["known"] == "0")
if not flyby:
    sys.exit("FAIL: the simulated hall has no fly-by anchor")
tags = {v: set(yaml.safe_load(open(os.path.join(data, v, "setup.yaml")))["rel_tag_positions"].keys()) for v in ("v0", "v1")}
refs_seen = set()
for v, other in (("v0", "v1"), ("v1", "v0")):
    inits = yaml.safe_load(open(os.path.join(work, "run", v, "anchor_init.yaml")))["anchors"]
    ids = [a["id"] for a in inits]
    if sorted(ids) != flyby:
        sys.exit(f"FAIL: {v} got ANCHOR_INIT for {ids}, expected each of the fly-by anchors {flyby} once")
    for a in inits:
        t = layout[a["id"]]
        err = math.dist(a["p_AinG"], (float(t["x_m"]), float(t["y_m"]), float(t["z_m"])))
        refs = set(a["ref_ids"])
        print(f"{v}: anchor {a['id']} at {err:.3f} m from the truth, references {sorted(refs)}")
        if err > 0.3:
            sys.exit(f"FAIL: {v}'s anchor {a['id']} is {err:.3f} m from its true position")
        if refs & tags[other]:
            sys.exit(f"FAIL: {v}'s ANCHOR_INIT {a['id']} has pair biases of {other}'s tags {sorted(refs & tags[other])}")
        if not refs & tags[v]:
            sys.exit(f"FAIL: {v}'s ANCHOR_INIT {a['id']} has no pair bias of its own tags")
        refs_seen |= refs
    last = {}
    for r in csv.DictReader(open(os.path.join(work, "run", v, "anchors.csv"))):
        last[int(r["id"])] = max(last.get(int(r["id"]), 0.0), float(r["t"]))
    if not set(flyby) <= set(last):
        sys.exit(f"FAIL: {v}'s estimator did not join {sorted(set(flyby) - set(last))}")
    kept = max(t for i, t in last.items() if i in flyby and i != removed)
    print(f"{v}: anchor {removed} last reported at {last[removed]:.1f} s, the other fly-by anchors until {kept:.1f} s")
    if not (last[removed] < 34.0 and kept > 37.0):
        sys.exit(f"FAIL: {v}'s estimator did not remove anchor {removed} at 33 s (the fleet mission's ESTIMATOR_CMD)")
    truth = [list(map(float, r[:4])) for r in csv.reader(l for l in open(os.path.join(data, v, "groundtruth.csv")) if l[0].isdigit())]
    tt = [r[0] for r in truth]
    se, n = 0.0, 0
    for r in csv.DictReader(open(os.path.join(work, "run", v, "estimate.csv"))):
        t = float(r["t"])
        i = bisect.bisect_left(tt, t)
        i = min((j for j in (i - 1, i) if 0 <= j < len(tt)), key=lambda j: abs(tt[j] - t))  # the nearest truth
        if abs(tt[i] - t) > 0.01:
            continue
        se += sum((float(r[k]) - truth[i][j]) ** 2 for j, k in ((1, "tx"), (2, "ty"), (3, "tz")))
        n += 1
    rmse = math.sqrt(se / max(n, 1))
    print(f"{v}: {n} poses, RMSE {rmse:.3f} m")
    if n < 100 or rmse > 0.5:
        sys.exit(f"FAIL: {v}'s estimate ({n} poses scored) RMSE {rmse:.3f} m")
if not (tags["v0"] <= refs_seen and tags["v1"] <= refs_seen):
    sys.exit(f"FAIL: the calibrations did not use both vehicles' tags (references {sorted(refs_seen)})")
PY
# The stop between a calibration and its publication, made exact: the journal without v1's records.
journal=$(ls "$WORK"/run/fleet_calibrator_state/*/calibrator_inputs.lcmlog 2>/dev/null | head -1)
[[ -n "$journal" ]] || fail "no journal of the fleet calibrator under $WORK/run/fleet_calibrator_state"
mkdir -p "$WORK/resend"
python3 - "$journal" "$WORK/resend/calibrator_inputs.lcmlog" <<'PY' || fail "see above"
import struct, sys
src, dst = sys.argv[1:]
data = open(src, "rb").read()
out, pos, kept, dropped = bytearray(), 0, {}, 0
while pos + 28 <= len(data):
    sync, num, utime, clen, dlen = struct.unpack(">IqqII", data[pos:pos + 28])
    if sync != 0xEDA1DA01:
        sys.exit("FAIL: the journal is not an LCM log")
    end = pos + 28 + clen + dlen
    ch = data[pos + 28:pos + 28 + clen].decode()
    if ch == "v1/ANCHOR_INIT":
        dropped += 1
    else:
        kept[ch] = kept.get(ch, 0) + 1
        out += data[pos:end]
    pos = end
open(dst, "wb").write(out)
print(f"journal: {sum(kept.values())} events kept ({kept.get('v0/ANCHOR_INIT', 0)} v0/ANCHOR_INIT), {dropped} v1/ANCHOR_INIT dropped")
if dropped != 3 or kept.get("v0/ANCHOR_INIT", 0) != 3:
    sys.exit("FAIL: expected 3 ANCHOR_INIT records per vehicle in the journal")
PY
"$BIN/calibrator" --fleet "$WORK/data/fleet.yaml" --state-dir "$WORK/resend" --config "$SRC/config/calibrator.yaml" \
  > "$WORK/resend.log" 2>&1 &
cal=$!
for _ in $(seq 300); do
  (( $(grep -c "had not been sent before the stop: sent now" "$WORK/resend.log") >= 3 )) && break
  kill -0 "$cal" 2>/dev/null || break
  sleep 0.1
done
kill -TERM "$cal" 2>/dev/null; wait "$cal"; crc=$?
(( crc == 0 )) || fail "the calibrator replaying the cut journal exited with $crc"
n1=$(grep -c "ANCHOR_INIT [0-9]* (t = [0-9.]* s) to v1 had not been sent before the stop: sent now" "$WORK/resend.log")
n0=$(grep -c " to v0 had not been sent" "$WORK/resend.log")
(( n1 == 3 && n0 == 0 )) || fail "after the cut journal: $n1 ANCHOR_INIT re-sent to v1 (expected 3), $n0 to v0 (expected 0)"
python3 - "$WORK/resend/calibrator_inputs.lcmlog" <<'PY' || fail "see above"
import struct, sys
data = open(sys.argv[1], "rb").read()
pos, n = 0, {"v0/ANCHOR_INIT": 0, "v1/ANCHOR_INIT": 0}
while pos + 28 <= len(data):
    _, _, _, clen, dlen = struct.unpack(">IqqII", data[pos:pos + 28])
    ch = data[pos + 28:pos + 28 + clen].decode()
    n[ch] = n.get(ch, 0) + 1
    pos += 28 + clen + dlen
print("journal after the restart:", {k: v for k, v in n.items() if k.endswith("ANCHOR_INIT")})
if n["v0/ANCHOR_INIT"] != 3 or n["v1/ANCHOR_INIT"] != 3:
    sys.exit("FAIL: the journal does not show each vehicle's three ANCHOR_INIT as sent once")
PY
echo "PASS"
