#!/usr/bin/env bash
# ./meshnav bench lcm's script at 10x on a 42 s flight: it exits 0, the estimator's POSEs answer
# (nearly) every IMU sample after its initialization and every RANGE, and bench_lcm.yaml has the
# latency, rate and CPU sections. Then --fleet at 10x on a 30 s flight of 2 vehicles among 16
# anchors: per vehicle the same sections, no message lost, every RANGE answered, a table row, and
# each vehicle on its own LCM bus (--bus per-vehicle, the default).
# Figures are not asserted (the machine is shared; docs/fleet.md).
#   bench_lcm_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -u
SRC=$1; BUILD=$2; WORK=$3
rm -rf "$WORK"
MESHNAV_BUILD_DIR="$BUILD" bash "$SRC/scripts/bench_lcm.sh" --duration-scale 0.3 --rate 10 --out "$WORK" > "$WORK.log" 2>&1 \
  || { cat "$WORK.log"; echo "FAIL: bench_lcm.sh exited $?"; exit 1; }
y="$WORK/bench_lcm.yaml"
[[ -s "$y" ]] || { echo "FAIL: no $y"; exit 1; }
cat "$y"
for key in imu_to_pose range_to_pose ranges_unanswered channels cpu_percent_of_a_core "  estimator:" "  IMU:" "  POSE:"; do
  grep -q "^$key" "$y" || { echo "FAIL: $y has no '$key'"; exit 1; }
done
n_imu=$(sed -n 's/^  IMU: {messages: \([0-9]*\),.*/\1/p' "$y")
n_answered=$(sed -n 's/^imu_to_pose: {n: \([0-9]*\),.*/\1/p' "$y")
n_range=$(sed -n 's/^  RANGE: {messages: \([0-9]*\),.*/\1/p' "$y")
n_range_answered=$(sed -n 's/^range_to_pose: {n: \([0-9]*\),.*/\1/p' "$y")
n_range_before=$(sed -n 's/^ranges_before_first_pose: \([0-9]*\).*/\1/p' "$y")
echo "IMU $n_imu, answered by a POSE $n_answered; RANGE $n_range, answered $n_range_answered, before the first POSE $n_range_before"
# The estimator initializes within the first seconds of the 42 s flight; after that every IMU
# sample gets its POSE.
(( n_answered >= n_imu / 2 )) || { echo "FAIL: only $n_answered of $n_imu IMU samples answered by a POSE"; exit 1; }
# Every RANGE after the estimator initialized is answered; those before it are not in RANGE -> POSE.
(( n_range_answered + n_range_before == n_range && n_range_before < n_range / 10 )) \
  || { echo "FAIL: $n_range_answered of $n_range RANGE answered ($n_range_before before the first POSE)"; exit 1; }

# ---- --fleet ----
FW="$WORK-fleet"
rm -rf "$FW"
MESHNAV_BUILD_DIR="$BUILD" bash "$SRC/scripts/bench_lcm.sh" --fleet --vehicles 2 --anchors 16 --hall 12,12,6 \
  --duration 30 --seed 3 --rate 10 --out "$FW" > "$FW.log" 2>&1 \
  || { cat "$FW.log"; echo "FAIL: bench_lcm.sh --fleet exited $?"; exit 1; }
python3 - "$FW" <<'PY' || exit 1
import os, sys, yaml
out = sys.argv[1]
text = open(os.path.join(out, "bench_lcm.yaml")).read()
y = yaml.safe_load(text)
for key in ("vehicles", "channels", "buses", "cpu_percent_of_a_core", "cpu_seconds", "scheduling", "published", "lost", "load_average"):
    if key not in y:
        sys.exit(f"FAIL: bench_lcm.yaml has no '{key}'")
if sorted(y["vehicles"]) != ["v0", "v1"]:
    sys.exit(f"FAIL: vehicles {sorted(y['vehicles'])}, expected v0, v1")
for v, f in y["vehicles"].items():
    for p in ("estimator", "imu_bridge", "uwb_bridge"):
        if f"{v}_{p}" not in y["cpu_percent_of_a_core"]:
            sys.exit(f"FAIL: no CPU figure of {v}_{p}")
    r, i, lost, pub = f["range_to_pose"], f["imu_to_pose"], y["lost"][v], y["published"][v]
    print(f"{v}: IMU published {pub['IMU']}, answered {i['n']}; RANGE published {pub['RANGE']}, tag-anchor ones answered {r['n']}; lost {lost}")
    if pub["IMU"] == 0 or pub["RANGE"] == 0:
        sys.exit(f"FAIL: {v}'s bridges published nothing")
    if i["n"] < pub["IMU"] / 2:
        sys.exit(f"FAIL: only {i['n']} of {pub['IMU']} IMU samples of {v} answered by a POSE")
    other = f.get("other_range_to_pose", {"n": 0})["n"]
    before = f["ranges_before_first_pose"]
    if r["n"] > f["fused_ranges"] or r["n"] + other + f["ranges_after_last_pose"] + before != pub["RANGE"] \
            or f["ranges_unanswered"] != 0 or before > pub["RANGE"] / 10:
        sys.exit(f"FAIL: {r['n']} + {other} of {pub['RANGE']} RANGE of {v} answered")
    if not 0 < r["n"] < pub["RANGE"]:
        sys.exit(f"FAIL: {r['n']} of {pub['RANGE']} RANGE of {v} taken as its tags' to anchors")
    if any(n != 0 for k, n in lost.items() if k != "ranges_after_last_pose"):
        sys.exit(f"FAIL: {v} lost messages: {lost}")
# The default --bus per-vehicle: the probe listened on one bus per vehicle, each carrying only its
# vehicle's channels; the CPU seconds of the fleet are reported.
if sorted(tuple(b["vehicles"]) for b in y["buses"]) != [("v0",), ("v1",)]:
    sys.exit(f"FAIL: buses {y['buses']}, expected one for v0 and one for v1")
for b in y["buses"]:
    v = b["vehicles"][0]
    if not b["channels"] or any(not (c.startswith(v + "/") or c == "LCM_SELF_TEST") for c in b["channels"]):
        sys.exit(f"FAIL: {v}'s bus carries {sorted(b['channels'])}")
if "per-vehicle LCM bus" not in text.splitlines()[0] or y["cpu_seconds"]["all"]["system"] <= 0:
    sys.exit("FAIL: the header names no per-vehicle bus, or no system CPU seconds")
rows = [l for l in open(os.path.join(out, "table.md")) if l.startswith("| v0 ") or l.startswith("| v1 ")]
if len(rows) != 2:
    sys.exit(f"FAIL: table.md has {len(rows)} vehicle rows")
PY
echo "PASS"
