#!/usr/bin/env bash
# tools/sanitizers/ctest_log.sh on sample ctest logs: the checked builds retry a failed test
# only when its own output shows LeakSanitizer's tracer crashing, and nothing else went wrong.
# Usage (ctest runs it so): bash ctest_log.sh /path/to/repo
set -u
source "$1/tools/sanitizers/ctest_log.sh"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
passed=0 failed=0
check() {  # NAME COMMAND...
  local name=$1
  shift
  if "$@"; then passed=$((passed + 1)); else failed=$((failed + 1)) && echo "FAIL: $name"; fi
}

# A run as ctest -j2 --output-on-failure prints it: cli.render_cli failed with two processes'
# tracer crashes in its output; api.shard0 passed.
cat > "$WORK/two_crashes_one_test" <<'LOG'
      Start 42: cli.render_cli
40/54 Test #37: core.shard3 ......................................   Passed   38.14 sec
      Start 47: api.shard0
45/54 Test #42: cli.render_cli ...................................***Failed   23.43 sec
IDENTICAL
FAIL: reproducible dpx: first render (Tracer caught signal 11: addr=0x25c8 pc=0x7fe320ae80f0
==17498==LeakSanitizer has encountered a fatal error.
FAIL: reproducible sgi: first render (Tracer caught signal 11: addr=0x25c8 pc=0x7f7c002e80f0
==17528==LeakSanitizer has encountered a fatal error.
FAIL: reproducible dpx: same bytes a second later
cli render_cli: 122 passed, 3 failed

      Start 48: api.shard1
46/54 Test #47: api.shard0 .......................................   Passed   10.71 sec

98% tests passed, 1 tests failed out of 54

The following tests FAILED:
	 42 - cli.render_cli (Failed)
Errors while running CTest
LOG
check "the failed test is named" [ "$(failed_tests "$WORK/two_crashes_one_test")" = cli.render_cli ]
check "its output is its own" [ "$(test_output "$WORK/two_crashes_one_test" cli.render_cli | grep -c .)" -eq 7 ]
check "a passed test printed nothing" [ -z "$(test_output "$WORK/two_crashes_one_test" api.shard0)" ]
check "two crashes in one test are retried" only_tracer_crashes "$WORK/two_crashes_one_test"

# A second failed test whose output has no crash: every failure stands.
sed -e 's/^46\/54 Test #47: api.shard0 \(\.*\)   Passed/46\/54 Test #47: api.shard0 \1***Failed/' \
  -e 's/^\t 42 - cli.render_cli (Failed)/&\n\t 47 - api.shard0 (Failed)/' \
  -e 's/^46\/54 Test #47.*/&\nExpected equality of these values/' "$WORK/two_crashes_one_test" > "$WORK/other_failure"
check "two failed tests are named" [ "$(failed_tests "$WORK/other_failure" | paste -sd,)" = cli.render_cli,api.shard0 ]
check "a failure without a crash stands" bash -c "source '$1/tools/sanitizers/ctest_log.sh'; ! only_tracer_crashes '$WORK/other_failure'"

# A crash beside a sanitizer's report: it stands.
sed 's/^IDENTICAL$/==1==ERROR: AddressSanitizer: heap-use-after-free/' "$WORK/two_crashes_one_test" > "$WORK/report"
check "a sanitizer's report stands" bash -c "source '$1/tools/sanitizers/ctest_log.sh'; ! only_tracer_crashes '$WORK/report'"

# No failure: nothing to retry.
sed '/^The following tests FAILED:/,$d' "$WORK/two_crashes_one_test" > "$WORK/none"
check "no failed test, no retry" bash -c "source '$1/tools/sanitizers/ctest_log.sh'; ! only_tracer_crashes '$WORK/none'"

echo "tools ctest_log: $passed passed, $failed failed"
[ $failed -eq 0 ]
