#!/usr/bin/env bash
# ./meshnav bench lcm: the estimator over LCM on this machine (issue 38 item 6). A simulated
# sequence is played in real time (or --rate X) by imu_bridge and uwb_bridge into the estimator
# process, inside a private network namespace (scripts/lcm_netns.sh); meshnav_lcm_probe receives
# IMU, RANGE and POSE and reports IMU -> POSE and RANGE -> POSE latency (median, p99, max; what
# each is: transport/latency_recorder.h), lost messages and messages per second; the CPU of each
# process is read from /proc/PID/stat (user + system time over its wall time). Options:
#   --seed N               sequence seed (default 1)
#   --duration-scale S     length of the flight, as meshnav_sim's (default 0.5: 70 s; --fleet: 1, 140 s)
#   --rate X               playback speed (default 1: real time, the figures that matter)
#   --out DIR              work folder (default out/bench-lcm); DIR/bench_lcm.yaml holds the figures
# A fleet over LCM (--fleet): meshnav_sim --vehicles N --anchors M --hall H writes the fleet, the
# launch file of meshnav_fleet_launch runs per vehicle its bridges and its estimator (--config) on
# its prefixed channels (v0/IMU, v0/POSE, ...) under scripts/supervisor.py, and the probe measures
# each vehicle (DIR/bench_lcm.yaml: vehicles:, cpu_percent_of_a_core:, published:, load_average:;
# DIR/table.md: one row per vehicle):
#   --fleet                5 vehicles x 100 anchors in a 40 x 40 x 10 m hall unless given:
#   --vehicles N  --anchors M  --hall X,Y,Z  --duration S (seconds of flight, meshnav_sim's)
#   --config FILE          estimator options (default config/fleet_scale.yaml)
#   --calibrator-for NAME  a calibrator and the fleet's mission.yaml serving vehicle NAME alone over
#                          LCM, so that it gets its fly-by anchors
#   --fleet-calibrator     one calibrator serving every vehicle (calibrator --fleet) and the fleet's
#                          mission.yaml on the first vehicle: every vehicle gets the fly-by anchors
#   --bus POLICY           per-vehicle (default: each vehicle's processes on their own LCM bus, the
#                          base port + 1 + its index) or shared (every process on one bus), as
#                          meshnav_fleet_launch --bus and meshnav_lcm_probe --bus
# With --fleet, RANGE -> POSE is over each vehicle's tag-anchor ranges; CPU = CPU seconds of a
# process's life over the wall seconds of the data (cpu_seconds: user and system seconds of each
# process and of all together, from /proc/PID/stat sampled every 0.5 s by one awk); lost = published but not received, or not
# answered by a POSE. `chrt -f 20 ./meshnav bench lcm --fleet` runs every process under SCHED_FIFO.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${MESHNAV_BUILD_DIR:-$ROOT/build}/bin"
seed=1; scale=""; rate=1; out="$ROOT/out/bench-lcm"
fleet=0; vehicles=5; anchors=100; hall=40,40,10; duration=""; config="$ROOT/config/fleet_scale.yaml"; calib_for=""
calib_fleet=0; bus=per-vehicle
args=("$@")
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seed) seed="$2"; shift 2 ;;
    --duration-scale) scale="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --fleet) fleet=1; shift ;;
    --vehicles) vehicles="$2"; shift 2 ;;
    --anchors) anchors="$2"; shift 2 ;;
    --hall) hall="$2"; shift 2 ;;
    --duration) duration="$2"; shift 2 ;;
    --config) config="$2"; shift 2 ;;
    --calibrator-for) calib_for="$2"; shift 2 ;;
    --fleet-calibrator) calib_fleet=1; shift ;;
    --bus) bus="$2"; shift 2 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "bench_lcm: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
if (( ! fleet )); then
  for o in --vehicles --anchors --hall --duration --config --calibrator-for --fleet-calibrator --bus; do
    [[ " ${args[*]} " == *" $o "* ]] && { echo "bench_lcm: $o needs --fleet" >&2; exit 2; }
  done
fi
[[ -n "$calib_for" && "$calib_fleet" == 1 ]] && { echo "bench_lcm: --calibrator-for and --fleet-calibrator exclude each other" >&2; exit 2; }
[[ "$vehicles" =~ ^[1-9][0-9]*$ ]] || { echo "bench_lcm: --vehicles expects a positive number, got '$vehicles'" >&2; exit 2; }
[[ "$bus" == per-vehicle || "$bus" == shared ]] || { echo "bench_lcm: --bus expects per-vehicle or shared, got '$bus'" >&2; exit 2; }
[[ -f "$config" ]] || { echo "bench_lcm: --config $config: no such file" >&2; exit 2; }
if [[ -z "${MESHNAV_BENCH_LCM_INSIDE:-}" ]]; then
  export MESHNAV_BENCH_LCM_INSIDE=1
  exec bash "$ROOT/scripts/lcm_netns.sh" bash "$0" "${args[@]}"
fi
mkdir -p "$out"
PIDS=()
SUP=""
cleanup() {
  # The supervisor stops its processes on SIGTERM (each in its own process group).
  if [[ -n "$SUP" ]] && kill -0 "$SUP" 2>/dev/null; then
    kill -TERM "$SUP" 2>/dev/null; for _ in $(seq 40); do kill -0 "$SUP" 2>/dev/null || break; sleep 0.25; done
  fi
  for p in "${PIDS[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
}
trap cleanup EXIT
fail() { echo "bench_lcm: $*" >&2; for f in "$out"/*.log; do echo "---- $f" >&2; tail -n 8 "$f" >&2; done; exit 1; }
now_us() { date +%s%6N; }
# cpu_s PID: user + system CPU seconds of a running process.
cpu_s() { awk -v hz="$(getconf CLK_TCK)" '{ print ($14 + $15) / hz }' "/proc/$1/stat"; }
HZ=$(getconf CLK_TCK)
# cpu_us_sy PID...: "PID USER_S SYSTEM_S RUN_NS WAIT_NS SLICES" of each running PID: its CPU
# seconds (/proc/PID/stat) and, summed over its threads (/proc/PID/task/*/schedstat), the time it
# ran, the time it waited on a run queue for a core and how often it was put on one. One grep and
# one awk for all (a sample of 16 processes every 0.5 s must not fork 50 processes itself on 2
# cores); a PID or thread gone is left out.
cpu_us_sy() {
  local files=() p
  for p in "$@"; do [[ -r /proc/$p/stat ]] && files+=("/proc/$p/stat" /proc/"$p"/task/*/schedstat); done
  (( ${#files[@]} )) || return 0
  grep -H '' "${files[@]}" 2>/dev/null | awk -v hz="$HZ" '
    { i = index($0, ":"); split(substr($0, 1, i - 1), f, "/"); n = split(substr($0, i + 1), a, " "); p = f[3]
      if (f[4] == "stat") { u[p] = a[14] / hz; s[p] = a[15] / hz } else { run[p] += a[1]; w[p] += a[2]; sl[p] += a[3] } }
    END { for (p in u) printf "%s %.2f %.2f %.0f %.0f %d\n", p, u[p], s[p], run[p], w[p], sl[p] }'
}

# ---- a fleet over LCM (--fleet) ---------------------------------------------------------------
run_fleet() {
  local data="$out/data" launch="$out/fleet_launch.yaml"
  local sim_args=(--vehicles "$vehicles" --anchors "$anchors" --hall "$hall" --seed "$seed")
  [[ -n "$duration" ]] && sim_args+=(--duration "$duration")
  [[ -n "$scale" ]] && sim_args+=(--duration-scale "$scale")
  echo "[bench lcm] simulate $vehicles vehicles x $anchors anchors, hall $hall, seed $seed${duration:+, ${duration} s}" >&2
  rm -rf "$data"
  "$BIN/meshnav_sim" "${sim_args[@]}" --out "$data" > "$out/sim.log" 2>&1 || fail "meshnav_sim failed"
  local calib_args=()
  [[ -n "$calib_for" ]] && calib_args=(--calibrator-for "$calib_for" --mission "$data/mission.yaml"
                                       --calibrator-config "$ROOT/config/calibrator.yaml")
  (( calib_fleet )) && calib_args=(--fleet-calibrator --mission "$data/mission.yaml"
                                   --calibrator-config "$ROOT/config/calibrator.yaml")
  # 10 s after the data: an estimator behind (a loaded machine, --rate 10) answers all it was sent.
  "$BIN/meshnav_fleet_launch" --fleet "$data/fleet.yaml" --out "$launch" --no-logging --estimator-config "$config" \
    --shutdown-delay 10 --bus "$bus" "${calib_args[@]}" \
    > "$out/fleet_launch.log" 2>&1 || fail "meshnav_fleet_launch failed"
  local prefixes
  prefixes=$(python3 -c 'import sys, yaml; print(",".join(v["name"] for v in yaml.safe_load(open(sys.argv[1]))["vehicles"]))' \
    "$data/fleet.yaml") || fail "cannot read $data/fleet.yaml"
  "$BIN/meshnav_lcm_probe" --fleet "$data/fleet.yaml" --bus "$bus" --out "$out/probe.yaml" --samples "$out/range_to_pose.csv" > "$out/probe.log" 2>&1 &
  local probe=$!; PIDS+=("$probe")
  local load_start; load_start=$(cut -d' ' -f1-3 /proc/loadavg)
  echo "[bench lcm] launch $launch at ${rate}x (vehicles $prefixes, $bus bus; load average $load_start)" >&2
  python3 "$ROOT/scripts/supervisor.py" "$launch" BIN="$BIN" RATE="$rate" > "$out/supervisor.log" 2>&1 &
  SUP=$!
  declare -A name_of usr sys run_ns wait_ns slices
  name_of[$probe]=lcm_probe
  : > "$out/load.txt"
  local n=0 name p u s l
  while kill -0 "$SUP" 2>/dev/null; do
    while read -r name p; do name_of[$p]=$name; done \
      < <(sed -n 's/^\[supervisor\] started \([^ ]*\) (pid \([0-9]*\)).*/\1 \2/p' "$out/supervisor.log")
    while read -r p u s r w c; do
      usr[${name_of[$p]}]=$u; sys[${name_of[$p]}]=$s; run_ns[${name_of[$p]}]=$r; wait_ns[${name_of[$p]}]=$w; slices[${name_of[$p]}]=$c
    done < <(cpu_us_sy "${!name_of[@]}")
    if (( n++ % 2 == 0 )); then read -r l _ < /proc/loadavg; echo "$l" >> "$out/load.txt"; fi
    sleep 0.5
  done
  local rc=0; wait "$SUP" || rc=$?
  SUP=""
  sleep 0.3
  kill -TERM "$probe"; wait "$probe" || fail "meshnav_lcm_probe failed"
  (( rc == 0 )) || fail "the fleet launch exited with $rc (supervisor.log)"
  if grep -E "^\[[^]]*_estimator\] .*\[error\]" "$out/supervisor.log" | head -n 3 >&2; then
    fail "an estimator reported an error: these figures are not the estimators' at work"
  fi
  {
    # The data's wall time: the flight (v0's imu.csv) over the rate. Each process's CPU seconds of
    # its whole life (start-up, the wait for the data and the drain after it included) over it.
    local span
    span=$(awk -F, -v r="$rate" '$1 ~ /^[0-9.]+$/ { if (f == "") f = $1; l = $1 } END { print (l - f) / (r > 0 ? r : 1) }' \
      "$data/v0/imu.csv")
    echo "cpu_percent_of_a_core:  # user + system CPU seconds of each process's life over the ${span} s of wall time of the data"
    for name in $(printf '%s\n' "${!usr[@]}" | sort); do
      awk -v n="$name" -v c="${usr[$name]}" -v d="${sys[$name]}" -v w="$span" \
        'BEGIN { printf "  %s: %.2f\n", n, (w > 0 ? 100 * (c + d) / w : 0) }'
    done
    echo "cpu_seconds:  # user and system CPU seconds of each process's life (the last sample, 0.5 s before its end at most)"
    for name in $(printf '%s\n' "${!usr[@]}" | sort); do echo "  $name: {user: ${usr[$name]}, system: ${sys[$name]}}"; done
    awk -v span="$span" -v u="${usr[*]}" -v s="${sys[*]}" \
      'BEGIN { nu = split(u, a, " "); ns = split(s, b, " "); for (i = 1; i <= nu; ++i) tu += a[i]; for (i = 1; i <= ns; ++i) ts += b[i]
             printf "  all: {user: %.1f, system: %.1f, wall_of_the_data: %.1f}\n", tu, ts, span }'
    echo "scheduling:  # over each process's threads at its last sample: seconds on a core, seconds waiting on a run queue for one, times put on one, mean wait per time [µs]"
    for name in $(printf '%s\n' "${!usr[@]}" | sort); do
      awk -v n="$name" -v r="${run_ns[$name]}" -v w="${wait_ns[$name]}" -v c="${slices[$name]}" \
        'BEGIN { printf "  %s: {run_s: %.2f, wait_s: %.2f, slices: %d, mean_wait_us: %.1f}\n", n, r / 1e9, w / 1e9, c, (c > 0 ? w / c / 1e3 : 0) }'
    done
    echo "published:  # what each bridge said it published"
    for v in ${prefixes//,/ }; do
      local ni nr
      ni=$(sed -n "s/^\[${v}_imu_bridge\] .*published IMU \([0-9]*\),.*/\1/p" "$out/supervisor.log" | tail -n 1)
      nr=$(sed -n "s/^\[${v}_uwb_bridge\] .*published RANGE \([0-9]*\).*/\1/p" "$out/supervisor.log" | tail -n 1)
      echo "  $v: {IMU: ${ni:-0}, RANGE: ${nr:-0}}"
    done
    echo "load_average: {start: \"$load_start\", end: \"$(cut -d' ' -f1-3 /proc/loadavg)\", 1min_samples: [$(paste -sd, "$out/load.txt")]}"
  } > "$out/fleet_extra.yaml"
  local served="$calib_for"; (( calib_fleet )) && served="the fleet"
  python3 - "$out" "$seed" "$vehicles" "$anchors" "$hall" "${duration:-default}" "$rate" "$config" "$served" "$bus" <<'PY'
import datetime, os, sys, yaml
out, seed, nv, na, hall, duration, rate, config, calib_for, bus = sys.argv[1:]
probe = yaml.safe_load(open(os.path.join(out, "probe.yaml")))
extra = yaml.safe_load(open(os.path.join(out, "fleet_extra.yaml")))
loads = extra["load_average"]["1min_samples"] or [0.0]
head = (f"# ./meshnav bench lcm --fleet, {datetime.datetime.utcnow():%Y-%m-%dT%H:%M:%SZ}, {nv} vehicles x {na} anchors, "
        f"hall {hall}, seed {seed}, duration {duration}, rate {rate}x, estimator config {config}, "
        f"{'a calibrator and mission for ' + calib_for + ', ' if calib_for else ''}{bus} LCM bus, {os.cpu_count()} cores")
lost = {}
rows = []
for v, f in probe["vehicles"].items():
    pub = extra["published"][v]
    got = f["channels"]
    lost[v] = {"IMU_not_received": pub["IMU"] - got.get("IMU", {}).get("messages", 0),
               "RANGE_not_received": pub["RANGE"] - got.get("RANGE", {}).get("messages", 0),
               "imus_unanswered": f["imus_unanswered"], "ranges_unanswered": f["ranges_unanswered"],
               "ranges_after_last_pose": f["ranges_after_last_pose"],
               "poses_without_imu": f["poses_without_imu"]}
    r, i = f["range_to_pose"], f["imu_to_pose"]
    cpu = extra["cpu_percent_of_a_core"]
    msgs = sum(c["per_s"] for c in got.values())
    l = lost[v]
    o = f.get("other_range_to_pose", {"n": 0, "p99_us": 0})
    rows.append(f"| {v} | {r['n']} | {r['median_us']:.0f} µs | {r['p99_us'] / 1e3:.2f} ms | {r['max_us'] / 1e3:.1f} ms "
                f"| {i['p99_us'] / 1e3:.2f} ms | {cpu.get(v + '_estimator', 0):.1f} | {cpu.get(v + '_imu_bridge', 0):.1f} / "
                f"{cpu.get(v + '_uwb_bridge', 0):.1f} | {msgs:.0f} | {l['IMU_not_received']} / {l['RANGE_not_received']} "
                f"| {l['imus_unanswered']} / {l['ranges_unanswered']} | {o['n']}, p99 {o['p99_us'] / 1e3:.2f} ms |")
with open(os.path.join(out, "bench_lcm.yaml"), "w") as y:
    y.write(head + "\n")
    y.write(open(os.path.join(out, "probe.yaml")).read())
    y.write(open(os.path.join(out, "fleet_extra.yaml")).read())
    y.write("lost:  # published - received by the probe; IMU / RANGE that no POSE answered\n")
    for v, l in lost.items():
        y.write("  %s: {%s}\n" % (v, ", ".join("%s: %d" % (k, n) for k, n in l.items())))
with open(os.path.join(out, "table.md"), "w") as t:
    t.write(f"{head[2:]}; load average (1 min) during the run: mean {sum(loads) / len(loads):.1f}, "
            f"max {max(loads):.1f}\n\n")
    t.write("| vehicle | tag-anchor RANGE | RANGE → POSE median | p99 | max | IMU → POSE p99 "
            "| estimator CPU [% of a core] | imu / uwb bridge CPU | messages/s | lost to the probe IMU / RANGE "
            "| unanswered IMU / RANGE | other RANGE (mesh, tag-tag) |\n")
    t.write("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n")
    t.write("\n".join(rows) + "\n")
    cs = extra["cpu_seconds"]["all"]
    t.write(f"\nprobe CPU {extra['cpu_percent_of_a_core'].get('lcm_probe', 0):.1f} % of a core; "
            f"all channels {sum(c['per_s'] for c in probe['channels'].values()):.0f} messages/s; "
            f"the fleet's processes and the probe: {cs['user']:.1f} s user, {cs['system']:.1f} s system CPU "
            f"over the {cs['wall_of_the_data']:.0f} s of the data\n")
    sch = extra.get("scheduling", {})
    def waits(suffix):
        w = [f["mean_wait_us"] for n, f in sch.items() if n.endswith(suffix)]
        return ("–" if not w else f"{min(w):.0f} µs" if len(w) == 1 else f"{min(w):.0f}–{max(w):.0f} µs")
    t.write(f"\nmean wait on a run queue for a core, per time put on one: estimators {waits('_estimator')}, "
            f"bridges {waits('_bridge')}, probe {waits('lcm_probe')}\n")
    t.write("\nwhere the tail is: tag-anchor RANGE answered later than 2 ms, per 10 s of data time "
            "(window start [s]: count)\n\n")
    for v, f in probe["vehicles"].items():
        w = f.get("range_to_pose_over_2ms_per_10s") or {}
        t.write(f"- {v}: " + (", ".join(f"{k}: {n}" for k, n in sorted(w.items())) or "none") + "\n")
PY
  cat "$out/bench_lcm.yaml"; echo; cat "$out/table.md"
  grep -q "imu_to_pose: {n: 0," "$out/bench_lcm.yaml" && fail "a vehicle's POSE answered no IMU sample: its estimator never initialized?"
  exit 0
}
if (( fleet )); then run_fleet; fi

scale="${scale:-0.5}"

echo "[bench lcm] simulate seed $seed (duration scale $scale)" >&2
"$BIN/meshnav_sim" --seed "$seed" --duration-scale "$scale" --out "$out/data" > "$out/sim.log" 2>&1 || fail "meshnav_sim failed"
"$BIN/estimator" --setup "$out/data/setup.yaml" --heartbeat 0.2 > "$out/estimator.log" 2>&1 &
EST=$!; PIDS+=("$EST")
"$BIN/meshnav_lcm_probe" --out "$out/probe.yaml" > "$out/probe.log" 2>&1 &
PROBE=$!; PIDS+=("$PROBE")
t_start=$(now_us)
T0=$(( t_start + 2000000 ))
echo "[bench lcm] play at ${rate}x from t0 = $T0 us (estimator, bridges, probe in $LCM_DEFAULT_URL)" >&2
for b in imu_bridge uwb_bridge; do
  "$BIN/$b" --dataset "$out/data" --rate "$rate" --t0-utime "$T0" --wait-for ESTIMATOR_STATUS --wait-timeout 30 \
    --progress 10 > "$out/$b.log" 2>&1 &
  PIDS+=("$!")
done
IMU=${PIDS[2]}; UWB=${PIDS[3]}
cpu_imu=0; cpu_uwb=0
while kill -0 "$IMU" 2>/dev/null || kill -0 "$UWB" 2>/dev/null; do
  kill -0 "$IMU" 2>/dev/null && cpu_imu=$(cpu_s "$IMU")
  kill -0 "$UWB" 2>/dev/null && cpu_uwb=$(cpu_s "$UWB")
  sleep 0.5
done
wait "$IMU" || fail "imu_bridge failed"
wait "$UWB" || fail "uwb_bridge failed"
sleep 0.5  # the estimator's last POSE on its way (bounded; nothing is waited for beyond it)
t_end=$(now_us)
kill -0 "$EST" 2>/dev/null || fail "the estimator exited before the end of the data (estimator.log)"
cpu_est=$(cpu_s "$EST"); cpu_probe=$(cpu_s "$PROBE")
kill -TERM "$PROBE"; wait "$PROBE" || fail "meshnav_lcm_probe failed"
kill -TERM "$EST"; wait "$EST" || fail "estimator exited with $? on SIGTERM"
wall_s=$(awk -v a="$t_start" -v b="$t_end" 'BEGIN { print (b - a) / 1e6 }')
{
  echo "# ./meshnav bench lcm, $(date -u +%Y-%m-%dT%H:%M:%SZ), seed $seed, duration scale $scale, rate ${rate}x, $(nproc) cores"
  cat "$out/probe.yaml"
  echo "cpu_percent_of_a_core:  # user + system over the ${wall_s} s of wall time from the estimator's start"
  for p in estimator:$cpu_est imu_bridge:$cpu_imu uwb_bridge:$cpu_uwb lcm_probe:$cpu_probe; do
    awk -v n="${p%%:*}" -v c="${p#*:}" -v w="$wall_s" 'BEGIN { printf "  %s: %.2f\n", n, 100 * c / w }'
  done
} > "$out/bench_lcm.yaml"
cat "$out/bench_lcm.yaml"
grep -q "imu_to_pose: {n: 0," "$out/bench_lcm.yaml" && fail "no POSE answered an IMU sample: the estimator never initialized?"
# A run whose estimator stopped or failed measured something else than the estimator at work.
if grep -q "\] \[error\]" "$out/estimator.log"; then
  grep "\] \[error\]" "$out/estimator.log" | head -n 3 >&2
  fail "the estimator reported an error: these figures are not the estimator's at work"
fi
exit 0
