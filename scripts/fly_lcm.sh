#!/usr/bin/env bash
# ./meshnav fly --lcm: the closed loop as processes over LCM (docs/closed_loop.md "Over LCM"):
# vehicle_sim, estimator, calibrator, mission, controller and logging from config/launch/fly.yaml
# through scripts/supervisor.py, in a private network namespace (scripts/lcm_netns.sh). Writes
# DIR/closed_loop.yaml (the metrics of the flight in one process, plus over_lcm, commands_late),
# the flight's files, DIR/controller_timing.yaml (loop jitter), DIR/cpu.yaml (CPU per process),
# DIR/log (logger), DIR/launch.log.
#   fly_lcm.sh --out DIR [--seed N] [--mission FILE] [--realtime] [--strategy S] [--gust-sigma S]
#              [--kill-estimator-at T]          drill: kill -9 the estimator at simulated time T [s];
#                                               the supervisor respawns it (from its checkpoint)
#              [--respawn-delay S]              the estimator's respawn delay (default 0.2; 1.0 with
#                                               --kill-estimator-at: a failsafe and a pose re-initialized)
#              [--anchor-off ID --anchor-off-at T] [--range-loss F --range-loss-from T]   drills
#              [--command-timeout S]            lock-step: wall time to wait for a command (0.05)
# Exit status: 0 landed without a crash; 3 crashed or not landed; 1 a failure (launch.log); 2 usage.
set -u
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${MESHNAV_BUILD_DIR:-$ROOT/build}/bin"
out=""; seed=1; mission="$ROOT/config/missions/paper_like_closed_loop.yaml"; kill_at=""; respawn_delay=""
vehicle_args=(); estimator_args=()
usage() { sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --mission) mission="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    --realtime) vehicle_args+=(--realtime); shift ;;
    --strategy) estimator_args+=(--strategy "$2"); shift 2 ;;
    --kill-estimator-at) kill_at="$2"; shift 2 ;;
    --respawn-delay) respawn_delay="$2"; shift 2 ;;
    --gust-sigma|--anchor-off|--anchor-off-at|--range-loss|--range-loss-from|--command-timeout|--max-duration)
      vehicle_args+=("$1" "$2"); shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "fly_lcm: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ -n "$out" ]] || { echo "fly_lcm: --out DIR is required (see --help)" >&2; exit 2; }
[[ -f "$mission" ]] || { echo "fly_lcm: --mission $mission: no such file" >&2; exit 2; }
if [[ -n "$kill_at" && ! "$kill_at" =~ ^[0-9]+$ ]]; then
  echo "fly_lcm: --kill-estimator-at wants whole seconds, got '$kill_at'" >&2; exit 2
fi
if [[ -z "${MESHNAV_FLY_LCM_INSIDE:-}" ]]; then
  export MESHNAV_FLY_LCM_INSIDE=1
  exec bash "$ROOT/scripts/lcm_netns.sh" bash "$0" --out "$out" --seed "$seed" --mission "$mission" \
    ${kill_at:+--kill-estimator-at "$kill_at"} ${respawn_delay:+--respawn-delay "$respawn_delay"} "${estimator_args[@]}" "${vehicle_args[@]}"
fi
[[ -z "$respawn_delay" ]] && respawn_delay=$([[ -n "$kill_at" ]] && echo 1.0 || echo 0.2)
for b in vehicle_sim estimator calibrator mission controller logging; do
  [[ -x "$BIN/$b" ]] || { echo "fly_lcm: $BIN/$b missing (build it)" >&2; exit 1; }
done
mkdir -p "$out"
# What a previous run left there: a checkpoint or journal would be resumed by the new processes.
rm -rf "$out/estimator_state" "$out/calibrator_state" "$out/log"
rm -f "$out/closed_loop.yaml" "$out/controller_timing.yaml" "$out/drill.log"
out="$(cd "$out" && pwd)"
SUP=""
cleanup() { [[ -n "$SUP" ]] && kill -TERM "$SUP" 2>/dev/null; }
trap cleanup EXIT
fail() { echo "fly_lcm: $*" >&2; [[ -f "$out/launch.log" ]] && tail -n 30 "$out/launch.log" >&2; exit 1; }
now_us() { date +%s%6N; }

"$BIN/vehicle_sim" --seed "$seed" --mission "$mission" --write-setup "$out" > "$out/setup.log" 2>&1 ||
  fail "vehicle_sim --write-setup failed: $(tail -n 3 "$out/setup.log")"
echo "[fly lcm] seed $seed, mission $mission, ${vehicle_args[*]:-lock-step} over $LCM_DEFAULT_URL; log in $out/launch.log" >&2
cd "$ROOT" || fail "cannot cd to $ROOT"
python3 "$ROOT/scripts/supervisor.py" "$ROOT/config/launch/fly.yaml" BIN="$BIN" OUT="$out" SEED="$seed" \
  MISSION="$mission" ESTIMATOR_RESPAWN_DELAY="$respawn_delay" VEHICLE_ARGS="${vehicle_args[*]:-}" ESTIMATOR_ARGS="${estimator_args[*]:-}" \
  > "$out/launch.log" 2>&1 &
SUP=$!
start=$(now_us)
if [[ -n "$kill_at" ]]; then
  # Waits on the vehicle's progress line of simulated time kill_at, then kills the estimator it started.
  until grep -q "\[vehicle_sim\].* t = ${kill_at} s " "$out/launch.log"; do
    kill -0 "$SUP" 2>/dev/null || fail "the launch ended before t = $kill_at s"
    (( $(now_us) - start < 900000000 )) || fail "no t = $kill_at s after 900 s"
    sleep 0.05
  done
  pid=$(sed -n 's/^\[supervisor\] started estimator (pid \([0-9]*\)).*/\1/p' "$out/launch.log" | tail -n 1)
  [[ -n "$pid" ]] || fail "no estimator pid in launch.log"
  kill -KILL "$pid" || fail "cannot kill the estimator (pid $pid)"
  echo "[fly lcm] killed the estimator (pid $pid) at t = $kill_at s" | tee -a "$out/drill.log" >&2
fi
# CPU of each process (user + system seconds from /proc/PID/stat, last read while it ran; a
# respawned process's pids add up), written to DIR/cpu.yaml as seconds and % of a core.
declare -A CPU_S=()
sample_cpu() {
  local name pid
  while read -r name pid; do
    [[ -r "/proc/$pid/stat" ]] || continue
    CPU_S["$name:$pid"]=$(awk -v hz="$(getconf CLK_TCK)" '{ print ($14 + $15) / hz }' "/proc/$pid/stat" 2>/dev/null || echo 0)
  done < <(sed -n 's/^\[supervisor\] started \([a-z_]*\) (pid \([0-9]*\)).*/\1 \2/p' "$out/launch.log")
}
next_progress=$(( $(now_us) + 10000000 ))
while kill -0 "$SUP" 2>/dev/null; do
  sample_cpu
  (( $(now_us) - start < 1800000000 )) || fail "the launch still runs after 1800 s"
  if (( $(now_us) >= next_progress )); then  # progress: the vehicle's newest 't = N s' line
    line=$(grep "\[vehicle_sim\].* t = [0-9]* s (" "$out/launch.log" | tail -n 1 | sed 's/.*\] t = /t = /')
    [[ -n "$line" ]] && echo "[fly lcm] $line" >&2
    next_progress=$(( $(now_us) + 10000000 ))
  fi
  sleep 0.2
done
wait "$SUP"; rc=$?; SUP=""
wall_s=$(awk -v a="$start" -v b="$(now_us)" 'BEGIN { print (b - a) / 1e6 }')
{
  echo "# CPU per process over the ${wall_s} s of the launch (user + system, last sample while it ran)"
  for key in "${!CPU_S[@]}"; do echo "${key%%:*} ${CPU_S[$key]}"; done | sort |
    awk -v w="$wall_s" '{ s[$1] += $2 } END { for (n in s) printf "%s: {cpu_s: %.1f, percent_of_a_core: %.1f}\n", n, s[n], 100 * s[n] / w }' | sort
} > "$out/cpu.yaml"
grep -E "\[(vehicle_sim|controller)\].*(stopped|tracking RMSE)" "$out/launch.log" | cut -c1-400 >&2
[[ -s "$out/closed_loop.yaml" ]] || fail "no closed_loop.yaml (supervisor exit $rc)"
grep -q "^crashed: false" "$out/closed_loop.yaml" && grep -q "^landed: true" "$out/closed_loop.yaml" || exit 3
(( rc == 0 )) || fail "supervisor exited with $rc"
exit 0
