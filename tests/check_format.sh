#!/usr/bin/env bash
# Fails (and lists the files) when a tracked C or C++ file differs from what clang-format makes
# of it with the repository's .clang-format. Fix with:
#   git ls-files '*.c' '*.h' '*.cpp' | xargs clang-format -i
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
command -v clang-format > /dev/null || { echo "check_format: clang-format is not installed"; exit 1; }
mapfile -t files < <(git ls-files '*.c' '*.h' '*.cpp')
bad=()
for f in "${files[@]}"; do
  clang-format --dry-run --Werror "$f" > /dev/null 2>&1 || bad+=("$f")
done
if ((${#bad[@]})); then
  echo "check_format: ${#bad[@]} of ${#files[@]} files are not clang-formatted:"
  printf '  %s\n' "${bad[@]}"
  exit 1
fi
echo "check_format: all ${#files[@]} C/C++ files are clang-formatted ($(clang-format --version | head -1))"
