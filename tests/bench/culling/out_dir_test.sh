#!/bin/bash
# out_dir_test.sh LANTERN_BENCH WORK_DIR: lantern-bench --out with a missing nested directory
# creates it and writes what it says it wrote; an --out that cannot be created fails at once,
# with a non-zero exit, naming it, and claims no write.
bench=$1 work=$2
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$work" && mkdir -p "$work" || exit 1
tiny=(--scenes fcc_small --size 32 --runs 1 --modes hzb)

out="$work/missing/nested"
log=$("$bench" "${tiny[@]}" --out "$out" 2>&1)
code=$?
echo "$log"
[ "$code" -eq 0 ] || fail "exit $code with a missing --out directory"
for f in culling_bench.csv culling_bench.svg; do
  [ -s "$out/$f" ] || fail "$out/$f was not written"
  grep -qF "wrote $out/$f" <<<"$log" || fail "no 'wrote $out/$f' line"
done
grep -q "cannot" <<<"$log" && fail "an error was printed"

blocker="$work/blocker"  # a regular file where a directory should be
echo "not a directory" >"$blocker"
log=$("$bench" "${tiny[@]}" --out "$blocker/sub" 2>&1)
code=$?
echo "$log"
[ "$code" -ne 0 ] || fail "exit 0 although $blocker/sub cannot be created"
[ "$code" -lt 128 ] || fail "crashed (exit $code)"
grep -qF "$blocker/sub" <<<"$log" || fail "the message does not name $blocker/sub"
grep -q "wrote" <<<"$log" && fail "claims a write that did not happen"
echo "ok"
