#!/usr/bin/env bash
# ./meshnav demo: simulate paper sequence 1, launch every process over LCM on loopback (in a
# private network namespace when the machine allows it), replay the sequence at 10x through the
# bridges with fly-by calibration of anchors 106-110 (mission config/missions/paper_s2.yaml),
# then evaluate against ground truth: results table on the terminal, CSVs and PNG plots in OUT.
#   scripts/demo.sh [--seed N] [--rate R] [--out DIR] [--strategy centralized|dp|dah]
#   scripts/demo.sh --real [--bag FILE] [--rate R] [--out DIR]   the real ISAS-Walk1 recording instead
#                   (../shared/data/real-isas-walk1/; scripts/demo_real.sh --help)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
for a in "$@"; do
  if [[ "$a" == --real ]]; then
    args=()
    for b in "$@"; do [[ "$b" == --real ]] || args+=("$b"); done
    exec "$ROOT/scripts/demo_real.sh" "${args[@]}"
  fi
done
BIN="${MESHNAV_BUILD_DIR:-$ROOT/build}/bin"
seed=1; rate=10; out="$ROOT/out/demo"; strategy=dah
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seed) seed="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --strategy) strategy="$2"; shift 2 ;;
    -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
say() { printf '\033[1m[demo]\033[0m %s\n' "$*" >&2; }
cd "$ROOT"
rm -rf "$out"
mkdir -p "$out"

say "1/4 simulating paper sequence $seed -> $out/dataset"
"$BIN/meshnav_sim" --seed "$seed" --out "$out/dataset" > "$out/sim.log" 2>&1 || { cat "$out/sim.log"; exit 1; }
"$BIN/dataset_to_lcmlog" --dataset "$out/dataset" --out "$out/dataset/sequence.lcmlog" >> "$out/sim.log" 2>&1 || true

# Estimator options with the chosen strategy.
sed "s/^strategy: .*/strategy: $strategy  # set by the demo/" config/estimator.yaml > "$out/estimator.yaml"

launch=config/launch/flyby.yaml
[[ -f "$launch" ]] || launch=config/launch/demo.yaml
say "2/4 launching the processes of $launch over LCM (replay at ${rate}x, about $((150 / rate + 8)) s)"
set +e
"$ROOT/scripts/lcm_netns.sh" /usr/bin/python3 "$ROOT/scripts/supervisor.py" "$launch" \
  DATASET="$out/dataset" OUT="$out/lcm" RATE="$rate" BIN="$BIN" ESTIMATOR_CONFIG="$out/estimator.yaml" \
  MISSION=config/missions/paper_s2.yaml > "$out/processes.log" 2>&1
rc=$?
set -e
if [[ $rc -ne 0 || ! -s "$out/lcm/estimate.csv" ]]; then
  tail -40 "$out/processes.log"
  echo "demo: the launch failed (exit $rc); full log: $out/processes.log" >&2
  exit 1
fi
[[ -f "$out/lcm/calibration.yaml" ]] || { [[ -f "$out/lcm/anchor_init.yaml" ]] && cp "$out/lcm/anchor_init.yaml" "$out/lcm/calibration.yaml"; }

say "3/4 the same sequence in one process (meshnav_run, deterministic) -> $out/run"
"$BIN/meshnav_run" --dataset "$out/dataset" --out "$out/run" --strategy "$strategy" \
  --mission config/missions/paper_s2.yaml > "$out/run.log" 2>&1 || { tail -20 "$out/run.log"; exit 1; }

say "4/4 evaluating the run over LCM against ground truth"
"$BIN/meshnav_eval" --dataset "$out/dataset" --run "$out/lcm" --only-flying
echo
say "deterministic in-process run for comparison:"
"$BIN/meshnav_eval" --dataset "$out/dataset" --run "$out/run" --only-flying --no-plots | sed -n '/^pose error/,/^orientation/p'
echo
say "done. Plots: $out/lcm/*.png; estimates: $out/lcm/estimate.csv, anchors.csv; process logs: $out/processes.log"
say "replay the recorded bus: ./meshnav replay $out/lcm/run.lcmlog   (or the input: $out/dataset/sequence.lcmlog)"
