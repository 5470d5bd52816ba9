#!/bin/sh
# Usage: sim_cli_expect_failure.sh PATTERN COMMAND [ARGS...]
# Passes when COMMAND exits non-zero and its output (stdout + stderr) contains PATTERN (fixed string).
pattern="$1"; shift
out=$("$@" 2>&1); rc=$?
if [ "$rc" -eq 0 ]; then echo "expected a non-zero exit status from: $*"; exit 1; fi
if ! printf '%s' "$out" | grep -qF -- "$pattern"; then echo "exit $rc but the message does not name '$pattern':"; echo "$out"; exit 1; fi
echo "ok: exit $rc, message names '$pattern'"
