#!/bin/sh
# Usage: cli_expect_refusal.sh PATTERN COMMAND [ARGS...]
# Passes when COMMAND refuses its command line: exit status 2 (a usage error, not a crash or a
# failure later on) and its output (stdout + stderr) contains PATTERN (fixed string).
pattern="$1"; shift
out=$("$@" 2>&1); rc=$?
if [ "$rc" -ne 2 ]; then echo "expected exit status 2, got $rc from: $*"; echo "$out"; exit 1; fi
if ! printf '%s' "$out" | grep -qF -- "$pattern"; then echo "exit 2 but the message does not name '$pattern':"; echo "$out"; exit 1; fi
echo "ok: exit 2, message names '$pattern'"
