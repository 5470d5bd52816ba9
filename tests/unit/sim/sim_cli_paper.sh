#!/bin/sh
# Usage: sim_cli_paper.sh MESHNAV_SIM OUT_DIR — a short paper-scenario dataset with outliers and no
# take-off prior: exit status 0, every dataset file written and non-empty, the outliers reported,
# and no initial_pose in setup.yaml.
set -e
sim="$1"; out="$2"
rm -rf "$out"
"$sim" --seed 3 --out "$out" --duration-scale 0.3 --outlier-fraction 0.1 --no-initial-pose > "$out.log" 2>&1 \
  || { cat "$out.log"; echo "meshnav_sim failed"; exit 1; }
grep -q "outliers injected" "$out.log" || { cat "$out.log"; echo "no outlier summary"; exit 1; }
for f in imu.csv baro.csv ranges.csv flight_state.csv groundtruth.csv setup.yaml truth.yaml; do
  [ -s "$out/$f" ] || { echo "missing or empty $f"; exit 1; }
done
[ "$(wc -l < "$out/ranges.csv")" -gt 100 ] || { echo "too few ranges"; exit 1; }
grep -q "initial_pose" "$out/setup.yaml" && { echo "--no-initial-pose still wrote initial_pose"; exit 1; }
echo "paper dataset ok"
