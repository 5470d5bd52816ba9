#!/usr/bin/env bash
# `./meshnav demo --real` end to end (scripts/demo_real.sh): the real ISAS-Walk1 recording imported,
# replayed through estimator + logging + imu_bridge + uwb_bridge over LCM in a private network
# namespace (scripts/lcm_netns.sh, as the other integration tests), evaluated against the
# SE(3)-aligned truth. Checks: the messages the bridges published all reached the logger, the
# estimate keeps the recording's Unix stamps and reaches the end of the data, the LCM run's ATE is
# within 10 % of the in-process run's, the table prints meshnav beside multilateration, the PNGs
# exist. First, with a copy of the script whose ../shared is empty: the missing recording is
# named with where to put it, exit 1, no traceback.
#
#   demo_real_test.sh SOURCE_DIR BIN_DIR WORK_DIR
#
# Without ../shared/data/real-isas-walk1/ISAS-Walk1.bag the real-data part is skipped (exit 77,
# "SKIP:"); with the environment variable CI set that is a failure. The demo waits on process exits
# (the supervisor stops estimator and logger once both bridges have played everything); this
# script waits on the demo's exit.
set -u
SRC=$(cd "$1" && pwd)
BIN=$(cd "$2" && pwd)
WORK=$3
BAG="$(cd "$SRC/.." && pwd)/shared/data/real-isas-walk1/ISAS-Walk1.bag"
rm -rf "$WORK"
mkdir -p "$WORK"

fail() {
  echo "FAIL: $*"
  [[ -f "$WORK/demo.log" ]] && { echo "---- demo output (last lines)"; tail -n 40 "$WORK/demo.log"; }
  [[ -f "$WORK/demo/processes.log" ]] && { echo "---- processes.log (last lines)"; tail -n 20 "$WORK/demo/processes.log"; }
  exit 1
}

echo "== the recording missing: a clear message, exit 1, no traceback"
mkdir -p "$WORK/norecording/repo/scripts"
cp "$SRC/scripts/demo_real.sh" "$WORK/norecording/repo/scripts/"
"$WORK/norecording/repo/scripts/demo_real.sh" --out "$WORK/norecording/out" > "$WORK/norecording.log" 2>&1
rc=$?
(( rc == 1 )) || fail "demo --real without the recording exited with $rc, not 1"
grep -q "the real recording is needed" "$WORK/norecording.log" || fail "no 'recording is needed' message"
grep -q "$WORK/norecording/shared/data/real-isas-walk1/ISAS-Walk1.bag" "$WORK/norecording.log" \
  || fail "the message does not say where to put the recording"
grep -q "Traceback" "$WORK/norecording.log" && fail "a traceback instead of a message"
[[ -e "$WORK/norecording/out" ]] && fail "an output folder was made although nothing could run"
echo "ok: $(head -n 1 "$WORK/norecording.log" | sed 's/\x1b\[[0-9;]*m//g')"

if [[ ! -f "$BAG" ]]; then
  if [[ -n "${CI:-}" ]]; then
    fail "shared data not present: $BAG; CI is set, so this is a failure, not a skip"
  fi
  echo "SKIP: shared data not present: $BAG (expected at ../shared beside the repository)"
  exit 77
fi

echo "== demo --real at 10x"
MESHNAV_BUILD_DIR="$(dirname "$BIN")" "$SRC/scripts/demo_real.sh" --out "$WORK/demo" --rate 10 > "$WORK/demo.log" 2>&1
rc=$?
(( rc == 0 )) || fail "demo --real exited with $rc"
D="$WORK/demo"
if grep -q "lcm_netns.sh: NOTE" "$D/processes.log"; then
  echo "NOTE: network namespaces are not permitted here: the processes ran on a private udpm port on the host"
else
  echo "ran in a private network namespace"
fi

# Nothing lost on the bus: the logger received every message the bridges published.
pub_imu=$(sed -n 's/.*published IMU \([0-9]*\).*/\1/p' "$D/processes.log" | tail -n 1)
pub_range=$(sed -n 's/.*published RANGE \([0-9]*\).*/\1/p' "$D/processes.log" | tail -n 1)
[[ "$pub_imu" == "$(( $(wc -l < "$D/dataset/imu.csv") - 1 ))" ]] || fail "imu_bridge published ${pub_imu:-?} of the imu.csv rows"
[[ "$pub_range" == "$(( $(wc -l < "$D/dataset/ranges.csv") - 1 ))" ]] || fail "uwb_bridge published ${pub_range:-?} of the ranges.csv rows"
grep -q "^  IMU: {messages: $pub_imu," "$D/lcm/summary.yaml" || fail "the logger did not receive all $pub_imu IMU messages"
grep -q "^  RANGE: {messages: $pub_range," "$D/lcm/summary.yaml" || fail "the logger did not receive all $pub_range RANGE messages"
echo "bus: IMU $pub_imu, RANGE $pub_range published and logged"

# Time stamps: the recording's own Unix seconds from the bag through the bridges and the logger.
first_range=$(sed -n 2p "$D/dataset/ranges.csv" | cut -d, -f1)
[[ "$first_range" == 1664959676.989318950 ]] || fail "ranges.csv starts at $first_range, not the bag's stamp 1664959676.989318950"
first_est=$(sed -n 2p "$D/lcm/estimate.csv" | cut -d, -f1)
last_est=$(tail -n 1 "$D/lcm/estimate.csv" | cut -d, -f1)
last_data=$(tail -n 1 "$D/dataset/imu.csv" | cut -d, -f1)
awk -v a="$first_est" -v b="$last_est" -v d="$last_data" 'BEGIN{exit !(a > 1664959676 && a < b && b >= d - 0.1)}' \
  || fail "the logged estimate spans $first_est .. $last_est s; expected Unix stamps up to the data's end $last_data s"
echo "estimate: $first_est .. $last_est s (data ends at $last_data s)"

# The table and the figures.
row() { sed 's/\x1b\[[0-9;]*m//g' "$WORK/demo.log" | awk -v n="$1" '$1 == n && $NF == "se3" {print $2; exit}'; }
ate_lcm=$(row meshnav); ate_ml=$(row multilateration)
[[ -n "$ate_lcm" && -n "$ate_ml" ]] || fail "the table with meshnav beside multilateration (se3) was not printed"
ate_run=$(/usr/bin/python3 -c 'import sys, yaml; print(yaml.safe_load(open(sys.argv[1]))["pose"]["position"]["rmse_m"])' \
          "$D/run/metrics.yaml") || fail "no in-process metrics.yaml"
echo "ATE (se3): LCM $ate_lcm m, in-process $ate_run m, multilateration $ate_ml m"
# 10 %: the in-motion alignment is tried every 0.5 s on the data that has arrived, so how the two
# bridges' messages interleave can start the filter 1.5 s earlier with another heading (measured at
# 10x before the gravity check: 0.266-0.284 m against 0.283 m in one process; with it 0.243 m in
# both, docs/real_data.md).
awk -v a="$ate_lcm" -v b="$ate_run" 'BEGIN{d = a - b; if (d < 0) d = -d; exit !(d <= 0.10 * b)}' \
  || fail "the LCM run's ATE $ate_lcm m is not within 10 % of the in-process run's $ate_run m"
awk -v a="$ate_lcm" 'BEGIN{exit !(a > 0 && a < 0.30)}' || fail "ATE $ate_lcm m (docs/real_data.md: 0.243 m)"
awk -v a="$ate_ml" 'BEGIN{exit !(a > 0.226 && a < 0.286)}' || fail "multilateration ATE $ate_ml m (README: 0.256 m)"
grep -q "Plots in $D/lcm/" "$WORK/demo.log" || fail "the demo does not say where the plots are"
for p in trajectory_xy.png position_error.png range_residuals.png; do
  [[ "$(head -c 4 "$D/lcm/$p" 2>/dev/null | od -An -c | tr -d ' ')" == "211PNG" ]] || fail "$D/lcm/$p is not a PNG"
  grep -q "$D/lcm/$p" "$WORK/demo.log" || fail "the summary does not list $p"
done
echo "PASS"
