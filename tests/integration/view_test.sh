#!/usr/bin/env bash
# The live view in headless Chromium (docs/view.md): view_server plays a small known flight
# (meshnav_view_make_log: POSE, GROUND_TRUTH, ANCHORS, RANGE, statuses), Chromium opens the page
# and takes a screenshot, and the vehicle's colour (#ff00ff, used for nothing else on the page)
# must cover the vehicle's disc. The same with a log without POSE must show none of that colour
# (the check can fail). The page's first frame is also read back from the DOM it dumps.
#   view_test.sh BIN_DIR WORK_DIR
# Exit 77 (skipped) only when no Chromium is installed. Waits are on conditions, each bounded.
set -u
BIN=$(cd "$1" && pwd)
WORK=$2
HERE=$(cd "$(dirname "$0")" && pwd)
rm -rf "$WORK"
mkdir -p "$WORK/tmp" "$WORK/home"
CHROME=$(command -v chromium || command -v chromium-browser || true)
if [[ -z "$CHROME" ]]; then
  echo "SKIP: no chromium on this machine (Debian package chromium; ./meshnav test installs it)"
  exit 77
fi
PID=""
cleanup() { [[ -n "$PID" ]] && kill "$PID" 2>/dev/null && wait "$PID" 2>/dev/null; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$WORK"/*.out "$WORK"/*.err; do [[ -f "$f" ]] && { echo "---- $f"; tail -n 15 "$f"; }; done
  exit 1
}

# view CASE LOG: serves LOG, waits until it is played, screenshots the page into CASE.png and dumps its DOM.
view() {
  local name=$1 log=$2
  "$BIN/view_server" --log "$log" --speed 0 --port 0 > "$WORK/$name.out" 2> "$WORK/$name.err" &
  PID=$!
  local i
  for i in $(seq 1 300); do
    grep -q "to its end" "$WORK/$name.out" 2>/dev/null && break
    kill -0 "$PID" 2>/dev/null || fail "$name: view_server exited early"
    sleep 0.1
  done
  grep -q "to its end" "$WORK/$name.out" || fail "$name: the log was not played within 30 s"
  URL=$(sed -n 's/^view: \(http[^ ]*\)$/\1/p' "$WORK/$name.out" | head -n 1)
  [[ -n "$URL" ]] || fail "$name: no URL printed"
  python3 -c "import urllib.request,sys; open(sys.argv[2],'wb').write(urllib.request.urlopen(sys.argv[1]).read())" \
    "${URL}api/state" "$WORK/$name.json" || fail "$name: GET /api/state failed"
  local chrome_args=(--headless --no-sandbox --disable-gpu --hide-scrollbars --no-first-run
                     --user-data-dir="$WORK/profile-$name" --window-size=1280,800 --virtual-time-budget=4000)
  TMPDIR="$WORK/tmp" HOME="$WORK/home" timeout 90 "$CHROME" "${chrome_args[@]}" --screenshot="$WORK/$name.png" "$URL" \
    > "$WORK/$name-chrome.out" 2>&1 || fail "$name: chromium --screenshot failed"
  [[ -s "$WORK/$name.png" ]] || fail "$name: no screenshot"
  TMPDIR="$WORK/tmp" HOME="$WORK/home" timeout 90 "$CHROME" "${chrome_args[@]}" --dump-dom "$URL" \
    > "$WORK/$name.html" 2> "$WORK/$name-chrome.err" || fail "$name: chromium --dump-dom failed"
  kill "$PID" 2>/dev/null
  wait "$PID"
  local rc=$?
  PID=""
  [[ $rc -eq 0 ]] || fail "$name: view_server exited $rc on SIGTERM (expected 0)"
}

"$BIN/meshnav_view_make_log" --out "$WORK/flight.lcmlog" --duration 20 > "$WORK/make.out" 2>&1 || fail "meshnav_view_make_log"
"$BIN/meshnav_view_make_log" --out "$WORK/nopose.lcmlog" --duration 20 --no-pose > "$WORK/make.out" 2>&1 \
  || fail "meshnav_view_make_log --no-pose"

view flight "$WORK/flight.lcmlog"
grep -q '"pose":{' "$WORK/flight.json" || fail "flight: /api/state has no pose"
grep -q '"state":"calibrated"' "$WORK/flight.json" || fail "flight: /api/state has no calibrated anchor"
grep -q '"residuals":{"epoch":0,"start":0,"rows":\[\[' "$WORK/flight.json" || fail "flight: /api/state has no residuals"
count=$(python3 "$HERE/png_colour_count.py" "$WORK/flight.png" ff00ff 8) || fail "flight: cannot read the PNG"
n=${count#pixels=}; n=${n%% *}
echo "flight: vehicle colour $count"
# The disc has radius 8 px: about 200 pixels; its heading line and the ellipse may cover some.
[[ $n -ge 60 ]] || fail "flight: the page shows no vehicle ($n pixels of #ff00ff, at least 60 expected)"
grep -q 'data-vehicle-drawn="1"' "$WORK/flight.html" || fail "flight: the page did not mark a drawn vehicle in its DOM"
grep -q 'calibrated' "$WORK/flight.html" || fail "flight: the anchors table does not show a calibrated anchor"

view nopose "$WORK/nopose.lcmlog"
count=$(python3 "$HERE/png_colour_count.py" "$WORK/nopose.png" ff00ff 8) || fail "nopose: cannot read the PNG"
n=${count#pixels=}; n=${n%% *}
echo "nopose: vehicle colour $count"
[[ $n -eq 0 ]] || fail "nopose: $n pixels of the vehicle's colour without any POSE (the check could not fail)"
grep -q 'data-vehicle-drawn' "$WORK/nopose.html" && fail "nopose: the page says it drew a vehicle without any POSE"
echo "PASS: the view draws the vehicle of a played log, and none without POSE"
