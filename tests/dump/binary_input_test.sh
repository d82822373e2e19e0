#!/bin/bash
# binary_input_test.sh WORK_DIR LANTERN_RENDER CONFIG.yaml DUMP: lantern-render given a file of
# binary bytes, as its input and as its configuration, fails with a message that holds only
# printable ASCII (file content escaped, e.g. \x8f) and is cut short.
work=$1 render=$2 config=$3 dump=$4
fail() { echo "FAIL: $*"; exit 1; }
mkdir -p "$work" && cd "$work" || exit 1
# 4 KiB of fixed pseudo-random bytes (no NUL-free or newline-free guarantee, like a real binary).
LC_ALL=C awk 'BEGIN { x = 12345; for (i = 0; i < 4096; ++i) {
  x = (x * 1103515245 + 12345) % 2147483648; printf "%c", int(x / 65536) % 256 } }' >random.bin
[ "$(wc -c <random.bin)" -eq 4096 ] || fail "random.bin is not 4096 bytes"

check() {  # check WHAT EXPECTED ARGS...: non-zero exit, EXPECTED in the output, no raw bytes
  local what=$1 expected=$2
  shift 2
  "$render" "$@" >out.txt 2>&1
  local code=$?
  LC_ALL=C cat -v out.txt
  [ "$code" -ne 0 ] || fail "$what: exit 0"
  [ "$code" -lt 128 ] || fail "$what: crashed (exit $code)"
  grep -qF -- "$expected" out.txt || fail "$what: expected '$expected'"
  local raw
  raw=$(LC_ALL=C tr -d '\040-\176\n' <out.txt | wc -c)
  [ "$raw" -eq 0 ] || fail "$what: $raw unprintable bytes in the output"
  local longest
  longest=$(awk '{ if (length($0) > n) n = length($0) } END { print n + 0 }' out.txt)
  [ "$longest" -le 400 ] || fail "$what: a line of $longest characters"
}
check "binary input" "not a LAMMPS text dump?" "$config" random.bin
grep -qF '\x' out.txt || fail "binary input: no escaped byte (\xNN) quoted"
check "binary configuration" "random.bin" random.bin "$dump"
echo "ok"
