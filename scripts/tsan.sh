#!/usr/bin/env bash
# ThreadSanitizer over the daemon's threaded tests (docs/TESTING.md, "ThreadSanitizer"): builds them with the
# `tsan` preset and runs them, then fails if any process wrote a report — the test programs and, with --whole,
# the colorlabd and colorlab-sim the integration tests start (a daemon stopped by a report can make its test
# fail in a way that does not say why; the report files do). Not part of CI.
#   scripts/tsan.sh [--whole] [CTEST ARGS...]    e.g. --repeat until-fail:3
# Without --whole: the HTTP server, the camera's frame pipeline and the daemon's thread-owning services
# (daemon_thread_services_tests), 51 compilations. With --whole: also the
# programs that link the whole daemon and the integration tests that run colorlabd, about 200 more.
# Runs under `setarch -R` (GCC 12's TSan cannot map its shadow memory when vm.mmap_rnd_bits is above 28) and
# `nice -n 19`.
set -euo pipefail
cd "$(dirname "$0")/.."
targets=(daemon_thread_services_tests daemon_http_server_tests camera_pipeline_test)
if [[ ${1:-} == --whole ]]; then
  shift
  # daemon_wal_bound_tests' 400 fsyncs take 50 s to over its 120 s ctest TIMEOUT under TSan on a busy machine.
  targets+=(daemon_unit_tests daemon_blob_service_tests daemon_wal_bound_tests daemon_http_robustness_tests
            integration_commit_hold_tests integration_worker_pool_tests integration_watchdog_hold_tests
            integration_event_stream_tests integration_crash_loop_tests integration_server_timing_tests
            integration_blob_tests colorlabd colorlab colorlab-sim colorlab_faultshim)
fi
cmake --preset tsan >/dev/null
nice -n 19 cmake --build --preset tsan -j2 --target "${targets[@]}"
# Every test of those programs and no other (names are gtest's Suite.Name; several programs share a suite name).
regex=$(ctest --test-dir build-tsan --show-only=json-v1 | python3 -c '
import json, os, re, sys
programs = set(sys.argv[1:])
names = [t["name"] for t in json.load(sys.stdin)["tests"]
         if t.get("command") and os.path.basename(t["command"][0]) in programs
         and not t["name"].endswith("_NOT_BUILT")]
print("^(" + "|".join(re.escape(n) for n in names) + ")$" if names else "^$no-test")
' "${targets[@]}")
reports=$(mktemp -d /tmp/colorlab-tsan-XXXXXX)
TSAN_OPTIONS="suppressions=$(pwd)/tests/tsan.supp halt_on_error=1 second_deadlock_stack=1"
export TSAN_OPTIONS="$TSAN_OPTIONS log_path=$reports/report"
status=0
setarch -R nice -n 19 ctest --test-dir build-tsan -R "$regex" -j1 --timeout 900 --output-on-failure "$@" || status=$?
if compgen -G "$reports/report*" >/dev/null; then
  echo "tsan.sh: ThreadSanitizer reports (one file per process):" >&2
  for f in "$reports"/report*; do echo "== $f" >&2; cat "$f" >&2; done
  exit 1
fi
rm -rf "$reports"
echo "tsan.sh: no ThreadSanitizer report"
exit "$status"
