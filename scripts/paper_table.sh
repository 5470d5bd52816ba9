#!/usr/bin/env bash
# Sequences 1..12 of the paper scenario: simulate, run the pipeline, evaluate, print the table.
# Called by `./meshnav paper-table` after the build. Options:
#   --seeds A-B            seed range (default 1-12)
#   --strategy S           centralized | dp | dah (default centralized)
#   --out DIR              output root (default out/paper-<strategy>)
#   --mission FILE         mission file for meshnav_run (fly-by calibration)
#   --config FILE          estimator options
#   --sim-args "..."       extra meshnav_sim options (e.g. "--outlier-fraction 0.1")
#   --run-args "..."       extra meshnav_run options (e.g. "--no-calibration")
#   --table-md FILE        also write the table as Markdown
#   --smooth               also smooth each run (meshnav_smooth) and print the smoothed estimate
#                          beside the filter's, per seed and on average (docs/smoother.md)
#   --fixed-lag            print the fixed-lag smoothed estimate (every run's estimate_smoothed.csv)
#                          beside the filter's, as --smooth does for the whole-recording smoother
#   --hardware-draws       sequence s flies other UWB modules (meshnav_sim --hardware-seed 1000+s)
#                          instead of the paper's one fixed set: figures over the simulator's
#                          hardware distribution (docs/smoother.md, "Consistency over hardware draws")
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${MESHNAV_BUILD_DIR:-$ROOT/build}/bin"
seeds="1-12"; strategy="centralized"; out=""; mission=""; config=""; sim_args=""; run_args_extra=""; table_md=""
smooth=0; fixed_lag=0; hardware_draws=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seeds) seeds="$2"; shift 2 ;;
    --strategy) strategy="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --mission) mission="$2"; shift 2 ;;
    --config) config="$2"; shift 2 ;;
    --sim-args) sim_args="$2"; shift 2 ;;
    --run-args) run_args_extra="$2"; shift 2 ;;
    --table-md) table_md="$2"; shift 2 ;;
    --smooth) smooth=1; shift ;;
    --fixed-lag) fixed_lag=1; shift ;;
    --hardware-draws) hardware_draws=1; shift ;;
    -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "paper_table: unknown option $1" >&2; exit 2 ;;
  esac
done
out="${out:-$ROOT/out/paper-$strategy}"
first="${seeds%-*}"; last="${seeds#*-}"
mkdir -p "$out"
for ((s = first; s <= last; s++)); do
  d="$out/$(printf 'seed%02d' "$s")"
  mkdir -p "$d"
  echo "[paper-table] seed $s: simulate, run ($strategy), evaluate -> $d" >&2
  # shellcheck disable=SC2086
  hw_args=""
  [[ $hardware_draws == 1 ]] && hw_args="--hardware-seed $((1000 + s))"
  "$BIN/meshnav_sim" --seed "$s" --out "$d/dataset" $hw_args $sim_args > "$d/sim.log" 2>&1 || { cat "$d/sim.log"; exit 1; }
  run_args=(--dataset "$d/dataset" --out "$d/run" --strategy "$strategy")
  [[ -n "$mission" ]] && run_args+=(--mission "$mission")
  [[ -n "$config" ]] && run_args+=(--config "$config")
  # shellcheck disable=SC2206
  [[ -n "$run_args_extra" ]] && run_args+=($run_args_extra)
  "$BIN/meshnav_run" "${run_args[@]}" > "$d/run.log" 2>&1 || { cat "$d/run.log"; exit 1; }
  if [[ $smooth == 1 ]]; then
    smooth_args=(--dataset "$d/dataset" --run "$d/run")
    [[ -n "$config" ]] && smooth_args+=(--config "$config")
    "$BIN/meshnav_smooth" "${smooth_args[@]}" > "$d/smooth.log" 2>&1 || { cat "$d/smooth.log"; exit 1; }
  fi
  "$BIN/meshnav_eval" --dataset "$d/dataset" --run "$d/run" --no-plots --only-flying > "$d/eval.log" 2>&1 \
    || { cat "$d/eval.log"; exit 1; }
done
batch=(--batch "$out")
[[ -n "$table_md" ]] && batch+=(--table-md "$table_md")
"$BIN/meshnav_eval" "${batch[@]}"
if [[ $smooth == 1 || $fixed_lag == 1 ]]; then
  # The filter and the smoother of each run, from the metrics.yaml meshnav_eval wrote (flying only).
  /usr/bin/python3 - "$out" "$first" "$last" <<'PY'
import sys, yaml
out, first, last = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
print("\nseed  filter pos [m]  ANEES  ori [deg]  |  smoothed pos [m]  ANEES  ori [deg]  |  ratio")
rows = []
for s in range(first, last + 1):
    m = yaml.safe_load(open(f"{out}/seed{s:02d}/run/metrics.yaml"))
    f, sm = m["pose"], m.get("pose_smoothed")
    if not f or not sm:
        print(f"{s:4d}  (no smoothed estimate scored)"); continue
    r = (f["position"]["rmse_m"], f["position"]["anees"], f["orientation"]["rmse_deg"],
         sm["position"]["rmse_m"], sm["position"]["anees"], sm["orientation"]["rmse_deg"])
    rows.append(r)
    print(f"{s:4d}  {r[0]:14.3f}  {r[1]:5.2f}  {r[2]:9.2f}  |  {r[3]:16.3f}  {r[4]:5.2f}  {r[5]:9.2f}  |  {r[3] / r[0]:5.2f}")
if rows:
    mean = [sum(r[i] for r in rows) / len(rows) for i in range(6)]
    print(f"mean  {mean[0]:14.3f}  {mean[1]:5.2f}  {mean[2]:9.2f}  |  {mean[3]:16.3f}  {mean[4]:5.2f}  {mean[5]:9.2f}  |  {mean[3] / mean[0]:5.2f}")
PY
fi
