#!/usr/bin/env bash
# Set up, build and run every test. Hardware-labelled tests skip themselves; their reasons are
# printed after the run, followed by one closing line "tests: N passed, N failed, N skipped".
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh dev

out=$(mktemp)
trap 'rm -f "$out"' EXIT
set +e
ctest --preset dev "$@" 2>&1 | tee "$out"
rc=${PIPESTATUS[0]}
set -e

log=build/Testing/Temporary/LastTest.log
if [[ -f $log ]] && grep -q '^\[  SKIPPED \]' "$log"; then
  echo
  echo "Skipped tests and why:"
  awk '/: Skipped$/ { getline reason; if (reason ~ /^\[  SKIPPED \]/) { name = reason; reason = "(no reason given)" } else { getline name }
                      sub(/^\[  SKIPPED \] /, "", name); sub(/ \([0-9]+ ms\)$/, "", name); print "  " name ": " reason }' "$log" |
    sort -u
fi

total=$(sed -n 's/.*tests passed, \([0-9]*\) tests\{0,1\} failed out of \([0-9]*\).*/\1 \2/p' "$out" | tail -1)
skipped=$(grep -c '(Skipped)' "$out" || true)
if [[ -n $total ]]; then
  read -r failed all <<<"$total"
  echo "tests: $((all - failed - skipped)) passed, $failed failed, $skipped skipped"
fi
exit "$rc"
