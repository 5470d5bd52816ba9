#!/usr/bin/env bash
# libFuzzer on every parser and decoder (fuzz/). Called by `./meshnav fuzz`. Options:
#   --seconds N      run each target N seconds (default 60)
#   --jobs J         build with -jJ (default MESHNAV_JOBS or 2)
#   --keep-going     do not stop at the first finding (libFuzzer -fork=1 -ignore_crashes=1): every
#                    crashing input is saved, and the table lists the distinct places (first
#                    meshnav frame of each report), for long runs past a known, unfixed finding
#   --list           print the target names and exit
#   TARGET ...       only these targets (default: all, plus launch_yaml, the Python launch parser)
# Builds with clang into build-fuzz/ (ASan + UBSan + libFuzzer; installs clang and its runtime
# libraries with apt-get when missing), runs each target on a working corpus build-fuzz/corpus/T
# seeded from fuzz/corpus/T, writes each log to build-fuzz/logs/T.log and a crashing input to
# build-fuzz/crashes/T-*. Prints a table; exit 1 when any target found something.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${MESHNAV_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
JOBS="${MESHNAV_JOBS:-2}"
seconds=60; targets=(); keep_going=0
# The target list is the one of fuzz/CMakeLists.txt: set(MESHNAV_FUZZ_TARGETS a b ...).
all_targets=$(sed -n '/^set(MESHNAV_FUZZ_TARGETS/,/)/p' "$ROOT/fuzz/CMakeLists.txt" | tr -d '()' |
              sed 's/^set *MESHNAV_FUZZ_TARGETS//' | xargs)
all_targets="$all_targets launch_yaml"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --jobs) JOBS="$2"; shift 2 ;;
    --keep-going) keep_going=1; shift ;;
    --list) tr ' ' '\n' <<<"$all_targets"; exit 0 ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz: unknown option $1" >&2; exit 2 ;;
    *) [[ " $all_targets " == *" $1 "* ]] || { echo "fuzz: unknown target $1 (one of: $all_targets)" >&2; exit 2; }
       targets+=("$1"); shift ;;
  esac
done
[[ "$seconds" =~ ^[0-9]+$ && "$seconds" -gt 0 ]] || { echo "fuzz: --seconds needs a positive integer" >&2; exit 2; }
[[ ${#targets[@]} -gt 0 ]] || read -r -a targets <<<"$all_targets"

say() { printf '\033[1m[meshnav fuzz]\033[0m %s\n' "$*" >&2; }

# clang and libFuzzer are needed here only, not by the normal build: installed on demand.
if [[ "${MESHNAV_SKIP_INSTALL:-0}" != 1 ]]; then
  missing=()
  for p in clang libclang-rt-dev; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [[ ${#missing[@]} -gt 0 ]]; then
    say "installing ${missing[*]}"
    sudo=(); [[ $(id -u) -ne 0 ]] && sudo=(sudo)
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
fi

native=()
for t in "${targets[@]}"; do [[ "$t" != launch_yaml ]] && native+=("fuzz_$t"); done
if [[ ${#native[@]} -gt 0 ]]; then
  if [[ ! -f "$BUILD/CMakeCache.txt" ]]; then
    say "configuring $BUILD (clang, libFuzzer, ASan, UBSan)"
    CC=clang CXX=clang++ cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" \
      -DMESHNAV_FUZZ=ON -DMESHNAV_BUILD_TESTS=OFF -DMESHNAV_BUILD_BENCHMARKS=OFF \
      -DMESHNAV_COMPONENTS="common;lcmtypes;transport;uwb_bridge;mission;fuzz" >/dev/null
  fi
  cmake "$BUILD" >/dev/null  # picks up targets added to fuzz/CMakeLists.txt since the last run
  say "building ${native[*]} with -j$JOBS (log: $BUILD/build.log)"
  cmake --build "$BUILD" -j"$JOBS" --target "${native[@]}" >"$BUILD/build.log" 2>&1 \
    || { grep -E 'error' "$BUILD/build.log" | head -20 >&2; say "build failed (see $BUILD/build.log)"; exit 1; }
fi

mkdir -p "$BUILD/logs" "$BUILD/crashes" "$BUILD/corpus"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
failed=0
rows=()
for t in "${targets[@]}"; do
  log="$BUILD/logs/$t.log"
  mkdir -p "$BUILD/corpus/$t"
  say "$t: ${seconds} s"
  set +e
  if [[ "$t" == launch_yaml ]]; then
    /usr/bin/python3 "$ROOT/fuzz/launch_yaml_fuzz.py" --seconds "$seconds" --seed "$(date +%s)" \
      --save "$BUILD/crashes" "$ROOT/fuzz/corpus/launch_yaml" >"$log" 2>&1
    rc=$?
    runs=$(sed -n 's/^\([0-9]*\) inputs.*/\1/p' "$log" | tail -1); cov="-"
  else
    mode=()
    [[ $keep_going == 1 ]] && mode=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
    before=$(ls "$BUILD/crashes" | grep -c "^$t-" || true)
    "$BUILD/bin/fuzz_$t" "${mode[@]}" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=2048 \
      -timeout=10 -artifact_prefix="$BUILD/crashes/$t-" "$BUILD/corpus/$t" "$ROOT/fuzz/corpus/$t" >"$log" 2>&1
    rc=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    [[ -n "$runs" ]] || runs=$(grep -ao '^#[0-9]*' "$log" | tail -1 | tr -d '#')  # fork mode: last status line
    cov=$(grep -ao 'cov: [0-9]*' "$log" | tail -1 | sed 's/cov: //')
    after=$(ls "$BUILD/crashes" | grep -c "^$t-" || true)
    if [[ $keep_going == 1 && $after -gt $before ]]; then
      # Distinct findings: the first meshnav frame of each new crash, replayed once.
      places=$(ls -t "$BUILD/crashes" | grep "^$t-" | head -n $((after - before)) | while read -r c; do
                 out=$("$BUILD/bin/fuzz_$t" "$BUILD/crashes/$c" 2>&1 || true)
                 grep -aom1 -E '(runtime error: .{0,60}|fuzz finding: .{0,80}|in meshnav::[^ (]*)' <<<"$out" || echo "?"
               done | sort | uniq -c | sed 's/^ */    /')
      printf '%s: %d crashing inputs, places:\n%s\n' "$t" $((after - before)) "$places" >>"$log"
      rc=1
    fi
  fi
  set -e
  result=ok
  if [[ $rc -ne 0 ]]; then result="FINDING (see $log)"; failed=1; fi
  rows+=("$(printf '%-18s %8s s %12s runs %8s edges  %s' "$t" "$seconds" "${runs:-?}" "${cov:-?}" "$result")")
done
printf '%s\n' "${rows[@]}"
exit $failed
