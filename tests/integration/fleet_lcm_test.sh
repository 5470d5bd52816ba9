#!/usr/bin/env bash
# A fleet over LCM (docs/fleet.md, "A fleet over LCM"): two vehicles of a short scaled fleet
# (meshnav_sim --vehicles 2) run by the launch file of meshnav_fleet_launch under
# scripts/supervisor.py in a private network namespace (scripts/lcm_netns.sh): per vehicle its
# bridges, estimator and logger, each with --channel-prefix <vehicle> and on the vehicle's own LCM
# bus (meshnav_fleet_launch's default --bus per-vehicle: the base port + 1 + k). Asserts that
#  - the launch exits 0 and every channel on the buses is a vehicle's (v0/..., v1/...; the probe
#    hears no unprefixed channel), each vehicle's POSE on its own v<k>/POSE;
#  - each vehicle's bus carries that vehicle's channels only (the probe listens on both buses, one
#    LCM instance each): v1's processes never received a datagram of v0's, and the reverse;
#  - each vehicle's estimate.csv (its logger, from v<k>/POSE) follows its OWN ground truth
#    (RMSE < 0.5 m) and not the other's (the vehicles fly in different parts of the hall): no
#    POSE crossed, and no estimator fused the other's IMU or ranges;
#  - no process counted a second publisher on its channels.
#   fleet_lcm_test.sh SOURCE_DIR BIN_DIR WORK_DIR
set -u
SRC=$1; BIN=$2; WORK=$3
if [[ -z "${MESHNAV_FLEET_TEST_INSIDE:-}" ]]; then
  rm -rf "$WORK"; mkdir -p "$WORK"
  export MESHNAV_FLEET_TEST_INSIDE=1
  exec bash "$SRC/scripts/lcm_netns.sh" bash "$0" "$@"
fi
fail() { echo "FAIL: $*"; for f in "$WORK"/*.log; do echo "---- $f"; tail -n 15 "$f"; done; exit 1; }
cd "$SRC" || fail "no $SRC"
"$BIN/meshnav_sim" --vehicles 2 --anchors 16 --hall 12,12,6 --duration 30 --seed 3 --out "$WORK/data" \
  > "$WORK/sim.log" 2>&1 || fail "meshnav_sim --vehicles 2 failed"
"$BIN/meshnav_fleet_launch" --fleet "$WORK/data/fleet.yaml" --out "$WORK/launch.yaml" \
  --estimator-config "$SRC/config/fleet_scale.yaml" > "$WORK/fleet_launch.log" 2>&1 || fail "meshnav_fleet_launch failed"
grep -q -- "--lcm-url, \"udpm://239.255.76.67:7669?ttl=0\"" "$WORK/launch.yaml" \
  || fail "v1's processes are not on their own bus (port 7669) in launch.yaml"
"$BIN/meshnav_lcm_probe" --channel-prefixes v0,v1 --out "$WORK/probe.yaml" > "$WORK/probe.log" 2>&1 &
probe=$!
python3 "$SRC/scripts/supervisor.py" "$WORK/launch.yaml" BIN="$BIN" OUT="$WORK/run" RATE=3 > "$WORK/supervisor.log" 2>&1
rc=$?
sleep 0.3
kill -TERM "$probe"; wait "$probe" || fail "meshnav_lcm_probe failed"
(( rc == 0 )) || fail "the fleet launch exited with $rc"
for p in v0_estimator v1_estimator v0_imu_bridge v1_uwb_bridge v0_logging v1_logging; do
  grep -q "^\[supervisor\] started $p " "$WORK/supervisor.log" || fail "$p was not started"
done
python3 - "$WORK" <<'PY' || fail "see above"
import bisect, math, os, sys, yaml
work = sys.argv[1]
probe = yaml.safe_load(open(os.path.join(work, "probe.yaml")))
channels = sorted(probe["channels"])
print("channels on the network:", ", ".join(channels))
# LCM_SELF_TEST: LCM's own start-up message on udpm
bad = [c for c in channels if not (c.startswith("v0/") or c.startswith("v1/") or c == "LCM_SELF_TEST")]
if bad:
    sys.exit("FAIL: channels that belong to no vehicle: %s" % bad)
buses = probe["buses"]
if sorted(tuple(b["vehicles"]) for b in buses) != [("v0",), ("v1",)]:
    sys.exit("FAIL: the probe's buses are %s, expected one for v0 and one for v1" % [b["vehicles"] for b in buses])
for b in buses:
    v = b["vehicles"][0]
    foreign = [c for c in b["channels"] if not (c.startswith(v + "/") or c == "LCM_SELF_TEST")]
    print(f"bus {b['url']}: {v}'s, {sum(b['channels'].values())} messages on {len(b['channels'])} channels")
    if foreign:
        sys.exit(f"FAIL: {v}'s bus {b['url']} carries {foreign}")
    if b["channels"].get(f"{v}/POSE", 0) == 0:
        sys.exit(f"FAIL: no {v}/POSE on {v}'s bus")
for v in ("v0", "v1"):
    for ch in ("IMU", "RANGE", "POSE", "ESTIMATOR_STATUS"):
        if probe["channels"].get(f"{v}/{ch}", {}).get("messages", 0) == 0:
            sys.exit(f"FAIL: nothing on {v}/{ch}")
    if probe["vehicles"][v]["imu_to_pose"]["n"] == 0:
        sys.exit(f"FAIL: no {v}/POSE answered a {v}/IMU sample")

def rows(path):
    out = []
    for line in open(path):
        if line.startswith("#") or line.startswith("t,") or not line.strip():
            continue
        f = [float(x) for x in line.replace(",", " ").split()[:4]]
        out.append(f)
    return out

truth = {v: rows(os.path.join(work, "data", v, "groundtruth.csv")) for v in ("v0", "v1")}
def rmse(est, gt):
    ts = [g[0] for g in gt]
    s = 0.0
    for e in est:
        i = min(max(bisect.bisect_left(ts, e[0]), 0), len(gt) - 1)
        g = gt[i]
        s += sum((e[k] - g[k]) ** 2 for k in (1, 2, 3))
    return math.sqrt(s / len(est))
for v, other in (("v0", "v1"), ("v1", "v0")):
    est = rows(os.path.join(work, "run", v, "estimate.csv"))
    if len(est) < 1000:
        sys.exit(f"FAIL: {v}/estimate.csv has {len(est)} poses")
    own, cross = rmse(est, truth[v]), rmse(est, truth[other])
    print(f"{v}: {len(est)} poses, RMSE against its truth {own:.3f} m, against {other}'s {cross:.2f} m")
    if not own < 0.5:
        sys.exit(f"FAIL: {v}'s estimate is {own:.2f} m RMSE off its own truth")
    if not cross > 1.0:
        sys.exit(f"FAIL: {v}'s estimate is within {cross:.2f} m of {other}'s truth: the vehicles are not told apart")
PY
if grep -E "second_publisher|publisher_changed" "$WORK/supervisor.log" "$WORK"/run/*/summary.yaml; then
  fail "a second publisher on a vehicle's channel"
fi
echo "PASS"
