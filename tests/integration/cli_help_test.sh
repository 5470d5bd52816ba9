#!/bin/sh
# Usage: cli_help_test.sh BIN_DIR BINARY...
# Every binary answers --help with exit 0 and a help text built from its option declarations
# (common/cli.h): an "Options:" list whose value options show their default or say they have none.
bin="$1"; shift
status=0
for b in "$@"; do
  out=$("$bin/$b" --help 2>&1); rc=$?
  if [ "$rc" -ne 0 ]; then echo "FAIL: $b --help exited with $rc"; status=1; continue; fi
  if ! printf '%s' "$out" | grep -q "^Options:"; then echo "FAIL: $b --help has no option list"; status=1; continue; fi
  if ! printf '%s' "$out" | grep -q -- "--help"; then echo "FAIL: $b --help does not list --help"; status=1; continue; fi
  echo "ok: $b --help ($(printf '%s\n' "$out" | grep -c -- '^  --') options)"
done
exit $status
