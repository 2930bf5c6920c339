#!/usr/bin/env bash
# Checks that every tracked C++ file is formatted by .clang-format (clang-format 14, from
# `tools/setup.sh --test`): the function-length rule of tests/docs reads the layout it gives.
# Prints each file that differs, with the command that fixes them, and exits 1.
set -euo pipefail
cd "$(dirname "$0")/.."
FORMAT=${CLANG_FORMAT:-clang-format-14}
command -v "$FORMAT" > /dev/null || { echo "check_format: $FORMAT not found (bash tools/setup.sh --test)" >&2; exit 2; }
bad=()
while IFS= read -r -d '' f; do
  "$FORMAT" --dry-run -Werror "$f" > /dev/null 2>&1 || bad+=("$f")
done < <(git ls-files -z -- '*.cpp' '*.hpp' '*.h')
if [ ${#bad[@]} -gt 0 ]; then
  printf 'check_format: not formatted: %s\n' "${bad[@]}" >&2
  echo "check_format: fix with: $FORMAT -i ${bad[*]}" >&2
  exit 1
fi
echo "check_format: ${FORMAT}: every tracked C++ file formatted"
