#!/usr/bin/env bash
# view_server refuses a log it cannot play before serving anything: a missing file, an empty one
# and one that is not an .lcmlog each give exit 1 and a message naming the file and the reason.
#   view_bad_log_test.sh BIN_DIR WORK_DIR
set -u
BIN=$(cd "$1" && pwd)
WORK=$2
rm -rf "$WORK"
mkdir -p "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
# refused NAME FILE PATTERN: view_server --log FILE exits 1 within 20 s with PATTERN in its output.
refused() {
  local name=$1 file=$2 pattern=$3 out rc
  out=$(timeout 20 "$BIN/view_server" --log "$file" --port 0 2>&1)
  rc=$?
  [[ $rc -eq 1 ]] || fail "$name: exit $rc (expected 1); output: $out"
  grep -qF -- "$pattern" <<< "$out" || fail "$name: the message does not say '$pattern': $out"
  grep -q "^view: http" <<< "$out" && fail "$name: it served before refusing the log"
  echo "ok: $name: exit 1, '$pattern'"
}
refused missing "$WORK/no_such.lcmlog" "no_such.lcmlog: no such file"
: > "$WORK/empty.lcmlog"
refused empty "$WORK/empty.lcmlog" "empty.lcmlog: no LCM event in it"
{ echo "t,x,y,z"; for i in $(seq 1 200); do echo "$i,0.1,0.2,0.3"; done; } > "$WORK/garbled.lcmlog"
refused garbled "$WORK/garbled.lcmlog" "garbled.lcmlog: no LCM event in it"
refused folder "$WORK" "not a regular file"
echo "PASS: every unplayable log refused with its reason"
