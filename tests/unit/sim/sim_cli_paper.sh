#!/bin/sh
# Usage: sim_cli_paper.sh MESHNAV_SIM OUT_DIR — a short paper-scenario dataset with outliers and no
# take-off prior: exit status 0, every dataset file written and non-empty, the outliers reported,
# and no initial_pose in setup.yaml; --hardware-seed draws other modules (other a-priori pair biases,
# its seed in truth.yaml) and the default stays the paper's fixed set.
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
"$sim" --seed 3 --out "$out.hw" --duration-scale 0.1 --hardware-seed 7 > "$out.hw.log" 2>&1 \
  || { cat "$out.hw.log"; echo "meshnav_sim --hardware-seed failed"; exit 1; }
grep -q "hardware_seed: 7$" "$out.hw/truth.yaml" || { echo "truth.yaml does not state hardware seed 7"; exit 1; }
grep -q "hardware_seed: 20230831$" "$out/truth.yaml" || { echo "the default hardware seed changed"; exit 1; }
grep "gamma:" "$out/setup.yaml" > "$out.g1"; grep "gamma:" "$out.hw/setup.yaml" > "$out.g2"
[ -s "$out.g1" ] || { echo "no pair biases in setup.yaml"; exit 1; }
cmp -s "$out.g1" "$out.g2" && { echo "--hardware-seed 7 wrote the default modules' pair biases"; exit 1; }
"$sim" --seed 3 --out "$out.bad" --hardware-seed -1 > "$out.bad.log" 2>&1 && { echo "--hardware-seed -1 accepted"; exit 1; }
echo "paper dataset ok"
