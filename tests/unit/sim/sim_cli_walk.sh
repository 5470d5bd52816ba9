#!/bin/sh
# Usage: sim_cli_walk.sh MESHNAV_SIM OUT_DIR — a walk dataset: every file but baro.csv and
# flight_state.csv, exit status 0.
set -e
sim="$1"; out="$2"
rm -rf "$out"
"$sim" --seed 2 --out "$out" --trajectory walk --hall 8,6,3 --anchor-layout random --tags 1 --known 3 --unknown 2 \
  --duration 40 --imu-grade consumer --bias-max 0.2 --outliers 0.1 --drop 0.03 --sigma-range 0.15
for f in imu.csv ranges.csv groundtruth.csv setup.yaml truth.yaml; do
  [ -s "$out/$f" ] || { echo "missing $f"; exit 1; }
done
for f in baro.csv flight_state.csv; do
  [ ! -e "$out/$f" ] || { echo "$f must not be written for a walk"; exit 1; }
done
grep -q "initial_pose" "$out/setup.yaml" && { echo "a walk has no initial_pose"; exit 1; }
echo "walk dataset ok"
