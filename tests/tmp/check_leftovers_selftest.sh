#!/bin/sh
# Usage: check_leftovers_selftest.sh ROOT
# The leftover check cannot pass vacuously: every test of this ctest run sees TMPDIR = the run folder
# under ROOT (also through Python's tempfile), and check_leftovers.sh fails on a leftover (naming it),
# on an unset TMPDIR and on a TMPDIR outside ROOT, and removes an empty run folder.
root="$1"
here=$(dirname "$0")
fail() { echo "FAIL: $*"; exit 1; }
case "${TMPDIR:-}" in
  "$root"/run-*) ;;
  *) fail "this test's TMPDIR='${TMPDIR:-}' is not a run folder under $root" ;;
esac
[ "$TMPDIR" = "${MESHNAV_TEST_TMPDIR:-}" ] || fail "TMPDIR=$TMPDIR but MESHNAV_TEST_TMPDIR=${MESHNAV_TEST_TMPDIR:-}"
py=$(python3 -c 'import tempfile; print(tempfile.gettempdir())') || fail "python3 failed"
[ "$py" = "$TMPDIR" ] || fail "Python's tempfile.gettempdir() is $py, not $TMPDIR"

fake=$(mktemp -d) || fail "mktemp -d"
trap 'rm -rf "$fake"' EXIT
run="$fake/run-selftest"
mkdir "$run" && touch "$run/meshnav_csv_123"
out=$(TMPDIR="$run" MESHNAV_TEST_TMPDIR="$run" MESHNAV_KEEP_TEST_FILES= sh "$here/check_leftovers.sh" "$fake") \
  && fail "a leftover passed: $out"
printf '%s' "$out" | grep -q "meshnav_csv_123" || fail "the leftover is not named: $out"
rm "$run/meshnav_csv_123"
TMPDIR="$run" MESHNAV_TEST_TMPDIR="$run" sh "$here/check_leftovers.sh" "$fake" >/dev/null || fail "an empty run folder failed"
[ ! -e "$run" ] || fail "the empty run folder was not removed"
env -u TMPDIR sh "$here/check_leftovers.sh" "$fake" >/dev/null && fail "an unset TMPDIR passed"
mkdir "$run"
TMPDIR="$fake" MESHNAV_TEST_TMPDIR="$fake" sh "$here/check_leftovers.sh" "$fake" >/dev/null \
  && fail "a TMPDIR outside ROOT/run-* passed"
echo "PASS: TMPDIR is the run folder; the check names leftovers and refuses an unset or foreign TMPDIR"
