#!/usr/bin/env bash
# Static analysis of Lantern's own code (core/, adaptor/, mini_md/): clang-tidy's bug-finding
# checks (bugprone-*, the clang static analyzer with its MPI checker) and cppcheck's warnings.
# Not part of CI (about 12 minutes on 2 cores); run it by hand after larger changes. Exits 1 when
# either tool reports something.
#
# Usage: bash tests/static_analysis.sh [BUILD_DIR]
#   BUILD_DIR  a configured build (default build); its compile_commands.json is (re)written.
# Needs clang-tidy (Debian's clang-tidy, 14) and cppcheck (2.10), and everything
# .ci/install-dependencies installs.
#
# Checks left out, and why:
#   bugprone-easily-swappable-parameters, -narrowing-conversions,
#   -implicit-widening-of-multiplication-result, -reserved-identifier, -branch-clone: style, or
#     hundreds of intended conversions in the pixel and index arithmetic;
#   bugprone-incorrect-roundings (int(x + 0.5)): every one rounds a value known to be >= 0 (a
#     colour channel, a weight, a fraction), where it is the round-half-up the images are defined by;
#   bugprone-misplaced-widening-cast: every one widens a product or sum of small ints (image widths
#     plus padding, Huffman code lengths, table indices) that cannot overflow;
#   clang-analyzer-optin.performance.Padding: struct layouts are chosen for the hot loops.
# Findings reviewed as false and kept out in the code: NOLINT (clang-tidy) and cppcheck-suppress
# comments, each saying why.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
cmake -S "$root" -B "$build" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON > /dev/null
work=$(mktemp -d /tmp/lantern_static.XXXXXX)
trap 'rm -rf "$work"' EXIT
# Only Lantern's own sources (tests and benchmarks hold GoogleTest's macros and throwaway code).
python3 - "$build/compile_commands.json" "$work/compile_commands.json" "$root" <<'PY'
import json, sys
root = sys.argv[3].rstrip("/") + "/"
own = [e for e in json.load(open(sys.argv[1]))
       if any(e["file"].startswith(root + d + "/") for d in ("core", "adaptor", "mini_md"))]
json.dump(own, open(sys.argv[2], "w"))
print(f"static analysis: {len(own)} translation units")
PY
checks='-*,bugprone-*,clang-analyzer-*,-bugprone-easily-swappable-parameters'
checks+=',-bugprone-narrowing-conversions,-bugprone-implicit-widening-of-multiplication-result'
checks+=',-bugprone-reserved-identifier,-bugprone-branch-clone,-bugprone-incorrect-roundings'
checks+=',-bugprone-misplaced-widening-cast,-clang-analyzer-optin.performance.Padding'
jobs=$(nproc)
run-clang-tidy -p "$work" -j "$jobs" -quiet -checks="$checks" \
  "^$root/(core|adaptor|mini_md)/.*\.(cpp|c)\$" > "$work/tidy.txt" 2> /dev/null || true
cppcheck --project="$work/compile_commands.json" --enable=warning,portability --inline-suppr \
  --suppress=missingIncludeSystem -q -j "$jobs" 2> "$work/cppcheck.txt" || true
tidy=$(sed 's/\x1b\[[0-9;]*m//g' "$work/tidy.txt" | grep -E '^/.*: (warning|error):' | sort -u || true)
cpp=$(grep -E '^/.*: (warning|error|portability):' "$work/cppcheck.txt" | sort -u || true)
echo "clang-tidy: $(printf '%s' "$tidy" | grep -c . || true) finding(s)"
[ -z "$tidy" ] || printf '%s\n' "$tidy"
echo "cppcheck: $(printf '%s' "$cpp" | grep -c . || true) finding(s)"
[ -z "$cpp" ] || printf '%s\n' "$cpp"
[ -z "$tidy$cpp" ]
