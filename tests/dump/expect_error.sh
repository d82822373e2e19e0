#!/bin/bash
# expect_error.sh WORK_DIR "EXPECTED TEXT" COMMAND...: passes when COMMAND exits non-zero (and
# was not killed by a signal) and its stderr contains EXPECTED TEXT.
work=$1 expected=$2
shift 2
mkdir -p "$work" && cd "$work" || exit 1
err=$("$@" 2>&1 >/dev/null)
code=$?
echo "$err"
if [ "$code" -eq 0 ]; then echo "FAIL: exit code 0"; exit 1; fi
if [ "$code" -gt 128 ]; then echo "FAIL: crashed (exit $code)"; exit 1; fi
if [[ "$err" != *"$expected"* ]]; then echo "FAIL: expected '$expected' in stderr"; exit 1; fi
echo "ok: exit $code with '$expected'"
