#!/bin/sh
# Usage: sim_cli_scaled_fleet.sh MESHNAV_SIM OUT_DIR — a scaled fleet: a dataset per vehicle,
# fleet.yaml, mission.yaml and anchors_layout.csv; the outage vehicle's tags hear no anchor in its
# window; exit status 0.
set -e
sim="$1"; out="$2"
rm -rf "$out"
"$sim" --vehicles 2 --anchors 16 --hall 16,16,6 --seed 3 --duration 30 --outage 1,10,15 --out "$out"
for f in fleet.yaml mission.yaml anchors_layout.csv v0/imu.csv v0/ranges.csv v1/ranges.csv v1/setup.yaml v1/truth.yaml; do
  [ -s "$out/$f" ] || { echo "missing $f"; exit 1; }
done
grep -q "name: v1, dataset: v1" "$out/fleet.yaml" || { echo "fleet.yaml does not list v1"; exit 1; }
grep -q "action: calibrate" "$out/mission.yaml" || { echo "mission.yaml calibrates nothing"; exit 1; }
[ "$(wc -l < "$out/anchors_layout.csv")" -eq 17 ] || { echo "anchors_layout.csv is not 16 anchors"; exit 1; }
# v1's tag-to-anchor ranges (its tags initiate: type T,A) stop over 10-15 s, v0's do not.
in_window() { awk -F, 'NR > 1 && $7 == "T" && $8 == "A" && $1 >= 10 && $1 <= 15' "$1" | wc -l; }
[ "$(in_window "$out/v1/ranges.csv")" -eq 0 ] || { echo "v1 heard anchors in its outage"; exit 1; }
[ "$(in_window "$out/v0/ranges.csv")" -gt 50 ] || { echo "v0 should range throughout"; exit 1; }
echo "scaled fleet ok"
