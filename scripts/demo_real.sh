#!/usr/bin/env bash
# ./meshnav demo --real: the real hand-held walk ISAS-Walk1 (UWB tag + IMU among five anchors, Vive
# truth; ../shared/data/real-isas-walk1/) through every process over LCM: import the ROS 1 bag
# (./meshnav import rosbag), replay it at RATE x through imu_bridge and uwb_bridge into the estimator
# and the logger (config/launch/demo.yaml, private network namespace), run the same data in one
# process (meshnav_run) for comparison, then evaluate against the SE(3)-aligned Vive truth: meshnav's
# ATE beside plain multilateration of the same ranges, PNG plots in OUT/lcm/.
#   scripts/demo_real.sh [--bag FILE] [--rate R] [--out DIR]
#   scripts/demo_real.sh --check-data [--bag FILE]   only check that the recording is there
# Default bag: ../shared/data/real-isas-walk1/ISAS-Walk1.bag beside the repository; OUT: out/demo-real.
# Exit status: 0 done, 1 a step failed or the recording is missing, 2 usage error.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${MESHNAV_BUILD_DIR:-$ROOT/build}/bin"
PY=/usr/bin/python3  # Debian's: python3-rosbag, python3-yaml, python3-matplotlib
SHARED_DIR="$(cd "$ROOT/.." && pwd)/shared/data/real-isas-walk1"
bag="$SHARED_DIR/ISAS-Walk1.bag"; rate=10; out="$ROOT/out/demo-real"; check_only=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --bag) bag="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --check-data) check_only=1; shift ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo --real: unknown option $1 (see ./meshnav demo --real --help)" >&2; exit 2 ;;
  esac
done
# Paths as the user gave them, relative to where the command was started (the script changes to the
# repository root below).
bag="$(realpath -m -- "$bag")"; out="$(realpath -m -- "$out")"
say() { printf '\033[1m[demo --real]\033[0m %s\n' "$*" >&2; }
die() { printf '\033[1;31m[demo --real] error:\033[0m %s\n' "$*" >&2; exit 1; }
[[ "$rate" =~ ^[0-9]+([.][0-9]+)?$ ]] && awk -v r="$rate" 'BEGIN{exit !(r > 0)}' \
  || { echo "demo --real: --rate must be a number > 0 (replay speed), got '$rate'" >&2; exit 2; }

# The recording: never copied into the repository, so it may be missing.
if [[ ! -f "$bag" ]]; then
  die "$(printf '%s\n' \
    "the real recording is needed and was not found: $bag" \
    "  demo --real replays ISAS-Walk1.bag (62.7 s hand-held walk, UWB + IMU + Vive truth; from the public" \
    "  repository of SFUISE, KIT-ISAS, RA-L 2023). Put it at" \
    "    $SHARED_DIR/ISAS-Walk1.bag" \
    "  (the folder shared/ beside the repository, with its README.md), or pass --bag FILE." \
    "  Without it, ./meshnav demo runs the simulated paper sequence.")"
fi
"$PY" -c 'import rosbag, yaml' 2>/dev/null \
  || die "$PY cannot import rosbag and yaml: install the Debian packages python3-rosbag and python3-yaml (./meshnav does it when run as root)"
(( check_only )) && exit 0

cd "$ROOT"
rm -rf "$out"
mkdir -p "$out"

say "1/5 importing $(basename "$bag") (ROS 1 bag) -> $out/dataset"
PYTHONPATH="$ROOT/tools" "$PY" -m meshnav_import rosbag --bag "$bag" --out "$out/dataset" > "$out/import.log" 2>&1 \
  || { tail -20 "$out/import.log"; die "the import failed; full log: $out/import.log"; }
grep -h "wrote \|counters:" "$out/import.log" | sed 's/^\[meshnav import\] /    /' >&2

# The recording is stamped in Unix seconds (1.66e9 s): the bridges play its first sample at the
# launch's shared wall time ${T0_UTIME} (DATA_T0), and every stamp stays the recording's own.
read -r data_t0 data_t1 < <("$PY" - "$out/dataset" <<'EOF'
import csv, os, sys
first, last = [], []
for name in ("imu.csv", "ranges.csv"):
    with open(os.path.join(sys.argv[1], name), newline="") as f:
        rows = [r[0] for r in csv.reader(f) if r and not r[0].startswith(("t", "#"))]
    first.append(rows[0]); last.append(rows[-1])
print(min(first, key=float), max(last, key=float))
EOF
)
span=$(awk -v a="$data_t0" -v b="$data_t1" 'BEGIN{printf "%.1f", b - a}')
say "2/5 replaying the recording over LCM at ${rate}x (${span} s of data from Unix time $data_t0, $(date -u -d "@${data_t0%.*}" '+%Y-%m-%d %H:%M:%S UTC'); about $(awk -v s="$span" -v r="$rate" 'BEGIN{printf "%.0f", s / r + 5}') s):"
say "    estimator, logging, imu_bridge, uwb_bridge (config/launch/demo.yaml) -> $out/lcm"
set +e
"$ROOT/scripts/lcm_netns.sh" "$PY" "$ROOT/scripts/supervisor.py" config/launch/demo.yaml \
  DATASET="$out/dataset" OUT="$out/lcm" RATE="$rate" BIN="$BIN" DATA_T0="$data_t0" > "$out/processes.log" 2>&1
rc=$?
set -e
if [[ $rc -ne 0 || ! -s "$out/lcm/estimate.csv" ]]; then
  tail -40 "$out/processes.log"
  die "the launch failed (exit $rc); full log: $out/processes.log"
fi
# What went over the bus: published by the bridges, received by the logger.
pub_imu=$(sed -n 's/.*published IMU \([0-9]*\).*/\1/p' "$out/processes.log" | tail -1)
pub_range=$(sed -n 's/.*published RANGE \([0-9]*\).*/\1/p' "$out/processes.log" | tail -1)
got_imu=$(sed -n 's/^  IMU: {messages: \([0-9]*\),.*/\1/p' "$out/lcm/summary.yaml")
got_range=$(sed -n 's/^  RANGE: {messages: \([0-9]*\),.*/\1/p' "$out/lcm/summary.yaml")
last_est=$(tail -n 1 "$out/lcm/estimate.csv" | cut -d, -f1)
say "    published IMU ${pub_imu:-?}, RANGE ${pub_range:-?}; the logger received IMU ${got_imu:-?}, RANGE ${got_range:-?};" \
    "$(( $(wc -l < "$out/lcm/estimate.csv") - 1 )) poses logged, the last at $last_est s (data ends at $data_t1 s)"
if ! awk -v a="$last_est" -v b="$data_t1" 'BEGIN{exit !(a >= b - 0.1)}'; then
  say "    WARNING: the estimate stops $(awk -v a="$last_est" -v b="$data_t1" 'BEGIN{printf "%.2f", b - a}') s before the data ends (the estimator was stopped before it caught up; try a lower --rate)"
fi

say "3/5 the same recording in one process (meshnav_run, deterministic) -> $out/run"
"$BIN/meshnav_run" --dataset "$out/dataset" --out "$out/run" > "$out/run.log" 2>&1 \
  || { tail -20 "$out/run.log"; die "meshnav_run failed; full log: $out/run.log"; }

say "4/5 evaluating the LCM run against the Vive truth (SE(3)-aligned, truth.yaml) with the multilateration baseline"
"$BIN/meshnav_eval" --dataset "$out/dataset" --run "$out/lcm" 2> "$out/eval.log" \
  || { tail -20 "$out/eval.log"; die "meshnav_eval failed; full log: $out/eval.log"; }
echo
say "5/5 evaluating the in-process run for comparison"
"$BIN/meshnav_eval" --dataset "$out/dataset" --run "$out/run" --no-plots > "$out/run/eval.txt" 2>> "$out/eval.log" \
  || { tail -20 "$out/eval.log"; die "meshnav_eval of the in-process run failed; full log: $out/eval.log"; }

# Summary from the two metrics.yaml files; without pose metrics (the estimator never initialized)
# a message and exit 1 instead of a table.
"$PY" "$ROOT/scripts/demo_compare.py" "$out/lcm/metrics.yaml" "$out/run/metrics.yaml" >&2 \
  || die "the comparison failed (above); the estimators' logs: $out/processes.log (LCM), $out/run.log (in-process)"
echo >&2
say "done. Plots in $out/lcm/:"
for p in trajectory_xy.png trajectory_3d.png position_error.png range_residuals.png orientation_error.png nees.png; do
  [[ -f "$out/lcm/$p" ]] && say "    $out/lcm/$p"
done
say "  (trajectory_xy: estimate against the SE(3)-aligned truth; position_error: error over time;"
say "   range_residuals: z − |p_T − p_A| per anchor along the estimate; the orientation error includes the"
say "   unknown rotation between the Vive tracker and the IMU, so it is not meaningful here)"
say "estimates: $out/lcm/estimate.csv; metrics: $out/lcm/metrics.yaml; process logs: $out/processes.log"
say "replay the recorded bus: ./meshnav replay $out/lcm/run.lcmlog"
