#!/usr/bin/env bash
# Outputs pinned before the library change (issue 11): each case of tests/golden/cases.txt
# rendered again must give the same PNG bytes and the same EXR floats; export-pov the same
# file; compare the same report. Usage (ctest): bash golden_cli.sh /path/to/abcube /path/to/repo
set -u
ABCUBE=$(realpath "$1")
REPO=$2
GOLDEN="$REPO/tests/golden"
WORK=$(mktemp -d "${TMPDIR:-/tmp}/abcube_golden.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
passed=0
failed=0
check() { local what=$1; shift; if "$@"; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $what" >&2; fi; }

cd "$GOLDEN" || exit 1
while read -r name scene args; do
  case "$name" in ''|'#'*) continue ;; esac
  # shellcheck disable=SC2086
  "$ABCUBE" render "$scene" -o "$WORK/$name.png" $args 2> "$WORK/err" &&
    "$ABCUBE" render "$scene" -o "$WORK/$name.exr" $args 2>> "$WORK/err"
  status=$?
  check "$name renders ($(head -c 300 "$WORK/err"))" [ $status -eq 0 ]
  check "$name: same PNG bytes" cmp -s "$WORK/$name.png" "$name.png"
  check "$name: same EXR floats" "$ABCUBE" compare --exact "$WORK/$name.exr" "$name.exr" > /dev/null
done < cases.txt

"$ABCUBE" export-pov hidden_point.json -o "$WORK/hidden_point.pov"
check "export-pov: same file" cmp -s "$WORK/hidden_point.pov" hidden_point.pov
"$ABCUBE" compare default_abuffer.png default_raytrace.png > "$WORK/compare.txt"
check "compare: exit 1 beyond --fail" [ $? -eq 1 ]
check "compare: same report" cmp -s "$WORK/compare.txt" compare.txt

# --exact tells equal floats from different ones
"$ABCUBE" compare --exact default_abuffer.exr default_abuffer.exr > /dev/null
check "compare --exact: an image equals itself" [ $? -eq 0 ]
"$ABCUBE" compare --exact default_abuffer.exr default_zbuffer.exr > /dev/null
check "compare --exact: two methods differ" [ $? -eq 1 ]

echo "golden: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
