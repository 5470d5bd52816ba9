#!/usr/bin/env bash
# The issue-12 targets across hosts (docs/results.md "Across hosts"): the demo flight (paper
# sequence 1, fly-by mission S2) through config/launch/multihost.yaml in real time,
#  1. loopback: every process in one network namespace (the reference);
#  2. across 11 namespaces (scripts/multihost_netns.sh) with each given netem spec, anchor107's and
#     anchor109's clocks off by +40 ms and -25 ms (corrected by TIME_SYNC);
# then meshnav_eval on each (pose RMSE, anchor errors) and meshnav_check_flyby on the calibrator's
# results. Needs root. About 3 minutes per run.
#   scripts/multihost_measure.sh OUT_DIR [SEED] [RATE] [NETEM ...]
# Default NETEM: "loss 5% delay 20ms 10ms" and "loss 20% delay 20ms 10ms". A spec may end in
# "|VAR=value ..." (e.g. "loss 20% delay 20ms 10ms|TIME_SYNC=0": without the clock correction).
# Environment: SKIP_LOOPBACK=1 keeps an earlier loopback run in OUT_DIR; PREFIX names the runs
# (default multihost: multihost1, multihost2, ...).
set -u
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/bin}"
OUT=$(mkdir -p "$1" && cd "$1" && pwd)
SEED=${2:-1}
RATE=${3:-1}
shift $(( $# >= 3 ? 3 : $# ))
SPECS=("$@")
(( ${#SPECS[@]} )) || SPECS=("loss 5% delay 20ms 10ms" "loss 20% delay 20ms 10ms")
"$BIN/meshnav_sim" --seed "$SEED" --out "$OUT/data" > "$OUT/sim.log" 2>&1 || { echo "meshnav_sim failed"; exit 1; }
t0=$(sed -n 2p "$OUT/data/imu.csv" | cut -d, -f1)
VARS=(BIN="$BIN" DATASET="$OUT/data" RATE="$RATE" MISSION_T0="$t0" MISSION="$ROOT/config/missions/paper_s2.yaml"
      ESTIMATOR_CONFIG="$ROOT/config/estimator.yaml" CALIBRATOR_CONFIG="$ROOT/config/calibrator.yaml")
cd "$ROOT" || exit 1
evaluate() {  # NAME
  "$BIN/meshnav_eval" --dataset "$OUT/data" --run "$OUT/$1" --no-plots --no-baseline > "$OUT/$1.eval.txt" 2>&1
  "$BIN/meshnav_check_flyby" --truth "$OUT/data/truth.yaml" --anchor-ids 106,107,108,109,110 \
    --anchor-init "$OUT/$1/calibration.yaml" --max-anchor-error 10 > "$OUT/$1.calib.txt" 2>&1
  echo "== $1"
  grep -iE "position RMSE|rmse|anchor" "$OUT/$1.eval.txt" | head -n 12
  cat "$OUT/$1.calib.txt"
}
if [[ "${SKIP_LOOPBACK:-0}" != 1 ]]; then
  echo "== loopback (one namespace)"
  "$ROOT/scripts/lcm_netns.sh" /usr/bin/python3 "$ROOT/scripts/supervisor.py" "$ROOT/config/launch/multihost.yaml" \
    "${VARS[@]}" OUT="$OUT/loopback" > "$OUT/loopback.log" 2>&1 || echo "loopback run: exit $?"
  evaluate loopback
fi
k=0
for spec in "${SPECS[@]}"; do
  k=$((k + 1))
  name="${PREFIX:-multihost}$k"
  netem=${spec%%|*}
  extra=()
  [[ "$spec" == *"|"* ]] && read -r -a extra <<< "${spec#*|}"
  echo "== across hosts, netem: $netem ${extra[*]}"
  echo "$spec" > "$OUT/$name.netem"
  "$ROOT/scripts/multihost_netns.sh" --netem "$netem" --logs "$OUT/$name.logs" "$ROOT/config/launch/multihost.yaml" \
    "${VARS[@]}" OUT="$OUT/$name" CLOCK_OFFSET_107=0.040 CLOCK_OFFSET_109=-0.025 "${extra[@]}" > "$OUT/$name.log" 2>&1 \
    || echo "$name: exit $?"
  evaluate "$name"
  grep -h "time sync: offset" "$OUT/$name.logs/anchor107.log" "$OUT/$name.logs/anchor109.log" | tail -n 2
  grep -o "RANGE:duplicate=[0-9]*\|out_of_sequence=[0-9]*" "$OUT/$name.logs/uav.log" | tail -n 2
  sed -n '/^channels:/,$p' "$OUT/$name.logs/switch.yaml"
done
