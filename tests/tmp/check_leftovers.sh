#!/bin/sh
# Usage: check_leftovers.sh ROOT
# Run by ctest after the last test (CTEST_CUSTOM_POST_TEST in <build>/CTestCustom.cmake, written by
# tests/CMakeLists.txt). TMPDIR is the run folder ROOT/run-* that tests/tmp/ctest_tmpdir.cmake made
# for this ctest run and gave to every test. Anything left in it is a test that did not clean up:
# listed by name, and the ctest run fails. An empty run folder is removed.
# It refuses to pass when TMPDIR is not such a folder (then nothing would have been checked).
# With MESHNAV_KEEP_TEST_FILES=1 the tests keep their files on purpose: listed, not a failure.
root="$1"
fail() { echo "tmp check: FAIL: $*"; exit 1; }
[ -n "$root" ] || fail "usage: check_leftovers.sh ROOT"
dir="${TMPDIR:-}"
[ -n "$dir" ] || fail "TMPDIR is not set: ctest did not read tests/tmp/ctest_tmpdir.cmake, nothing was checked"
[ "$dir" = "${MESHNAV_TEST_TMPDIR:-}" ] || fail "TMPDIR=$dir is not the run folder MESHNAV_TEST_TMPDIR=${MESHNAV_TEST_TMPDIR:-}"
case "$dir" in
  "$root"/run-*) ;;
  *) fail "TMPDIR=$dir is not a run folder under $root" ;;
esac
[ -d "$dir" ] || fail "the run folder $dir does not exist (removed by a test?)"
n=$(ls -A "$dir" | wc -l)
if [ "$n" -eq 0 ]; then
  rmdir "$dir"
  echo "tmp check: the tests left nothing in their TMPDIR ($dir)"
  exit 0
fi
if [ "${MESHNAV_KEEP_TEST_FILES:-}" = 1 ]; then
  echo "tmp check: MESHNAV_KEEP_TEST_FILES=1: $n entries kept in $dir:"
  ls -A "$dir" | sed 's/^/  /'
  exit 0
fi
echo "tmp check: FAIL: the tests left $n entries in their TMPDIR $dir (kept to look at):"
ls -A "$dir" | sed 's/^/  /'
echo "tmp check: a test that writes files must remove them (C++: meshnav::test::TempDir in"
echo "tests/support/test_util.h; Python: tempfile.TemporaryDirectory; shell: mktemp -d and trap; docs/contributing.md)"
exit 1
