#!/usr/bin/env bash
# Builds the libFuzzer harnesses of tests/fuzz with clang 14 under ASan + UBSan, and runs each one
# for a while from its committed seed corpus (tests/fuzz/corpus/HARNESS). Not part of CI.
#
# Usage: bash tests/fuzz/run_fuzzers.sh [BUILD_DIR [SECONDS [HARNESS...]]]
#   BUILD_DIR  default build-fuzz; SECONDS per harness, default 600 (0: build only);
#   HARNESS    fuzz_config fuzz_lammps_dump fuzz_h5md fuzz_python_publish (default: all four).
# The working corpus grows in BUILD_DIR/fuzz-corpus/HARNESS (the committed seeds are not touched);
# crashes, leaks of time or memory are written to BUILD_DIR/fuzz-crashes/HARNESS/ and each run's
# log to BUILD_DIR/fuzz-logs/HARNESS.log. Reproduce one: BUILD_DIR/tests/fuzz/HARNESS CRASH_FILE.
# Needs clang-14 and libclang-rt-14-dev (Debian), and everything .ci/install-dependencies installs.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$root/build-fuzz}
seconds=${2:-600}
shift $(($# > 2 ? 2 : $#))
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(fuzz_config fuzz_lammps_dump fuzz_h5md fuzz_python_publish)

launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
# Every target is compiled for coverage (fuzzer-no-link) and with the sanitizers; the harnesses
# link libFuzzer itself (tests/fuzz/CMakeLists.txt).
mkdir -p "$build"
CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_C_FLAGS=-fsanitize=fuzzer-no-link" "-DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link" \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1" \
  -DLANTERN_SANITIZE=address,undefined -DLANTERN_FUZZ=ON -DLANTERN_BUILD_BENCHMARKS=OFF \
  -DLANTERN_BUILD_MINI_MD=OFF -DLANTERN_BUILD_EXAMPLES=OFF -DLANTERN_WITH_FORTRAN=OFF \
  "${launcher[@]}" > "$build/configure.log"
cmake --build "$build" -j "$(nproc)" --target "${harnesses[@]}"
[ "$seconds" -gt 0 ] || exit 0

# Open MPI leaks at exit (see tests/run_sanitized.sh), so leak detection is off; every other ASan
# and UBSan report stops the run and keeps the input.
export ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LP_NUM_THREADS=1
status=0
for h in "${harnesses[@]}"; do
  corpus=$build/fuzz-corpus/$h crashes=$build/fuzz-crashes/$h/ log=$build/fuzz-logs/$h.log
  mkdir -p "$corpus" "$crashes" "$(dirname "$log")"
  cp -n "$root/tests/fuzz/corpus/$h/"* "$corpus/" 2> /dev/null || true
  echo "== $h: ${seconds} s from $(ls "$corpus" | wc -l) inputs"
  # -rss_limit_mb: an input that makes the reader allocate gigabytes is a finding too.
  if "$build/tests/fuzz/$h" "$corpus" -max_total_time="$seconds" -rss_limit_mb=3072 \
    -timeout=20 -artifact_prefix="$crashes" -print_final_stats=1 > "$log" 2>&1; then
    echo "   no crash: $(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}') executions"
  else
    status=1
    echo "   FAILED (see $log; inputs in $crashes):"
    grep -E "ERROR|SUMMARY|runtime error|Test unit written" "$log" | head -5 | sed 's/^/   /'
  fi
done
exit $status
