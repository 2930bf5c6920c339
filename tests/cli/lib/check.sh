# Sourced by the tests/cli scripts: a work folder removed on exit ($WORK) and the counters.
#   check WHAT COMMAND...   counts COMMAND's success, or prints "FAIL: WHAT"
# A script ends with: echo "NAME: $passed passed, $failed failed"; [ "$failed" -eq 0 ]
WORK=$(mktemp -d "${TMPDIR:-/tmp}/abcube_${CLI_TEST:-cli}.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
passed=0
failed=0
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*"; }
check() { local what=$1; shift; if "$@"; then ok; else bad "$what"; fi; }
