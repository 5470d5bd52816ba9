#!/usr/bin/env bash
# The live view over LCM (docs/view.md), in a private network namespace (scripts/lcm_netns.sh):
# view_server listens; meshnav_publish_sequence publishes 300 POSE (x = i mm) and an ANCHORS
# (anchors 201, 202) after every 10th; the state endpoint must show all 300 POSE, the last one's
# position, the path and both anchors as estimated. Malformed messages on POSE are then counted in
# the counters the page shows, and view_server keeps serving and stops with exit 0 on SIGTERM. It
# serves on 127.0.0.1 by default, and refuses a request that names another host (DNS rebinding).
#   view_live_test.sh BIN_DIR WORK_DIR
# Waits are on conditions (a printed line, the state endpoint's contents), each bounded.
set -u
BIN=$(cd "$1" && pwd)
WORK=$2
SRC=$(cd "$(dirname "$0")/../.." && pwd)
if [[ -z "${MESHNAV_VIEW_LIVE_INSIDE:-}" ]]; then
  export MESHNAV_VIEW_LIVE_INSIDE=1
  exec bash "$SRC/scripts/lcm_netns.sh" bash "$0" "$@"
fi
rm -rf "$WORK"
mkdir -p "$WORK"
PID=""
cleanup() { [[ -n "$PID" ]] && kill "$PID" 2>/dev/null; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$WORK"/*.out "$WORK"/*.err; do [[ -f "$f" ]] && { echo "---- $f"; tail -n 15 "$f"; }; done
  exit 1
}
# state EXPR: evaluates the Python expression EXPR on the state endpoint's JSON `j` (exit 0 when true).
state() {
  python3 - "$URL" "$1" <<'PY'
import json, sys, urllib.request
j = json.loads(urllib.request.urlopen(sys.argv[1] + 'api/state').read())
sys.exit(0 if eval(sys.argv[2]) else 1)
PY
}
wait_state() {
  local i
  for i in $(seq 1 200); do state "$1" && return 0; sleep 0.1; done
  return 1
}

"$BIN/view_server" --port 0 > "$WORK/view.out" 2> "$WORK/view.err" &
PID=$!
for i in $(seq 1 100); do grep -q "^view: http" "$WORK/view.out" && break; sleep 0.1; done
URL=$(sed -n 's/^view: \(http[^ ]*\)$/\1/p' "$WORK/view.out" | head -n 1)
[[ -n "$URL" ]] || fail "view_server printed no URL"
state "j['source']['mode'] == 'live' and j['pose'] is None" || fail "a fresh live view is not empty"
[[ "$URL" == http://127.0.0.1:* ]] || fail "the view does not serve on 127.0.0.1 by default: $URL"
# Another site's name for this address (DNS rebinding) is refused; the page itself is served.
code=$(python3 - "$URL" <<'PY'
import sys, urllib.error, urllib.request
try:
    urllib.request.urlopen(urllib.request.Request(sys.argv[1] + 'api/state', headers={'Host': 'evil.example'}))
    print(200)
except urllib.error.HTTPError as e:
    print(e.code)
PY
)
[[ "$code" == 403 ]] || fail "a request for Host evil.example got $code (expected 403)"
python3 -c "import sys, urllib.request; b = urllib.request.urlopen(sys.argv[1]).read(); sys.exit(0 if b'view.js' in b else 1)" "$URL" \
  || fail "GET / does not serve the page"

"$BIN/meshnav_publish_sequence" --count 300 --rate 500 --record "$WORK/sent.csv" > "$WORK/publish.out" 2>&1 \
  || fail "meshnav_publish_sequence"
wait_state "j['pose'] is not None and j['pose']['n'] == 300" || fail "the view did not get all 300 POSE"
state "abs(j['pose']['p'][0] - 0.299) < 1e-9 and len(j['path']['rows']) > 10" || fail "wrong last pose or no path"
state "sorted((a['id'], a['state']) for a in j['anchors']) == [(201, 'estimated'), (202, 'estimated')]" \
  || fail "anchors 201 and 202 are not shown as estimated"

"$BIN/meshnav_publish_garbage" --channel POSE --count 5 > "$WORK/garbage.out" 2>&1 || fail "meshnav_publish_garbage"
wait_state "j['counters'].get('POSE:decode_error', 0) == 5" || fail "the 5 malformed POSE are not counted"
state "j['pose']['n'] == 300" || fail "a malformed POSE reached the view"
kill "$PID"
wait "$PID"
rc=$?
PID=""
[[ $rc -eq 0 ]] || fail "view_server exited $rc on SIGTERM (expected 0)"
echo "PASS: the live view shows what LCM carries and counts what it refuses"
