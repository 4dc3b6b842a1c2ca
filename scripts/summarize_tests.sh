#!/usr/bin/env bash
# Prints every failing test case and one closing line "tests: N passed, N failed".
# Exits non-zero when a test failed or no test ran at all.
set -uo pipefail
results_dir=${1:?usage: summarize_tests.sh TEST_RESULTS_DIR}
summary=$(catkin_test_results --verbose "$results_dir")
status=$?
echo "$summary" | grep -vE '^Summary:' | grep -E 'FAIL|ERROR|failure|error' || true
line=$(echo "$summary" | grep -E '^Summary:')
echo "$line"
total=$(echo "$line" | sed -E 's/Summary: ([0-9]+) tests.*/\1/')
errors=$(echo "$line" | sed -E 's/.* ([0-9]+) errors.*/\1/')
failures=$(echo "$line" | sed -E 's/.* ([0-9]+) failures.*/\1/')
failed=$((errors + failures))
echo "tests: $((total - failed)) passed, $failed failed"
if [ "$total" -eq 0 ]; then echo "no test ran"; exit 1; fi
exit $status
