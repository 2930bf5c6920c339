# Reading a ctest log of the checked builds (tools/sanitize.sh sources this; the test
# tools.ctest_log holds it to sample logs): which tests failed, what each printed, and
# whether every failure was LeakSanitizer's tracer crashing at a process's exit.
sanitizer_report='ERROR: AddressSanitizer|runtime error:|ERROR: LeakSanitizer: detected memory leaks'
tracer_crash='LeakSanitizer has encountered a fatal error'

failed_tests() {  # LOG: the names ctest lists under "The following tests FAILED:"
  sed -n '/^The following tests FAILED:/,$p' "$1" | sed -nE 's/^[[:space:]]*[0-9]+ - (.*) \([^()]*\)$/\1/p'
}

test_output() {  # LOG NAME: what --output-on-failure printed under NAME's result line, up to
  # the next test's line (ctest prints a finished test's output whole, even with -j)
  awk -v name="$2" '
    /^[[:space:]]*[0-9]+\/[0-9]+ +Test +#[0-9]+: / {
      here = $0; sub(/^[^:]*: /, "", here); sub(/ .*/, "", here); inside = (here == name); next
    }
    /^[[:space:]]*Start +[0-9]+: / || /^[0-9]+% tests passed/ { inside = 0 }
    inside' "$1"
}

only_tracer_crashes() {  # LOG: no sanitizer's report, and every failed test's output holds the
  # tracer's crash (one test may run many processes, and more than one may crash)
  local name failed=0
  ! grep -qE "$sanitizer_report" "$1" || return 1
  while IFS= read -r name; do
    failed=$((failed + 1))
    test_output "$1" "$name" | grep -q "$tracer_crash" || return 1
  done < <(failed_tests "$1")
  [[ $failed -gt 0 ]]
}
