#!/bin/sh
# meshnav_run on a folder whose estimate.csv is a link to /dev/full (every write fails with ENOSPC,
# as on a full disk): it must exit 1 and name estimate.csv, not exit 0 with a torn file (issue 36).
set -u
bin="$1"
d=$(mktemp -d "${TMPDIR:-/tmp}/run_write_error.XXXXXX") || exit 1
trap 'rm -rf "$d"' EXIT
"$bin/meshnav_sim" --seed 1 --duration 30 --out "$d/ds" > "$d/sim.log" 2>&1 || { cat "$d/sim.log"; exit 1; }
mkdir -p "$d/run" && ln -s /dev/full "$d/run/estimate.csv"
"$bin/meshnav_run" --dataset "$d/ds" --out "$d/run" --no-calibration > "$d/run.log" 2>&1
rc=$?
if [ "$rc" -ne 1 ]; then echo "expected exit 1, got $rc"; cat "$d/run.log"; exit 1; fi
if ! grep -q "estimate.csv: write failed" "$d/run.log"; then echo "exit 1 but no message naming estimate.csv:"; cat "$d/run.log"; exit 1; fi
echo "ok: exit 1, $(grep -o 'estimate.csv: write failed[^)]*)' "$d/run.log" | head -1)"
