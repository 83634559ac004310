#!/usr/bin/env bash
# AddressSanitizer + UBSan over the test suite (docs/TESTING.md, "AddressSanitizer and UBSan"): builds the `asan`
# preset and runs its unit and conformance tests with the test preset's ASAN_OPTIONS, LSAN_OPTIONS and UBSAN_OPTIONS,
# then fails if any process wrote a report — the test programs and the colorlabd, colorlab-sim and colorlab CLI they
# start (a daemon stopped by a report can fail its test in a way that does not say why; the report files do). Not part
# of CI (the whole tree is about 500 compilations under the sanitizers).
#   scripts/asan.sh [--integration] [--target T]... [--no-build] [CTEST ARGS...]    e.g. --repeat until-fail:2
# --integration: the integration label too, without the Blender renders (programs verify_*blender*), the Debian package
# (packaging.*: an mmdebstrap chroot) and the soak. --target: build only the named targets (repeatable; the test
# programs build what they link) and run only their tests; the tests of programs not built are left out, not
# failed. --no-build: run what build-asan/ holds (e.g. while another shell builds the rest).
# Runs under `nice -n 19`.
set -euo pipefail
cd "$(dirname "$0")/.."
labels="unit|conformance"
targets=()
build=1
while [[ $# -gt 0 ]]; do
  case $1 in
    --integration) labels="unit|conformance|integration"; shift ;;
    --target) targets+=("$2"); shift 2 ;;
    --no-build) build=0; shift ;;
    *) break ;;
  esac
done
if [[ $build == 1 ]]; then
  cmake --preset asan >/dev/null
  nice -n 19 cmake --build --preset asan -j2 ${targets[@]:+--target "${targets[@]}"}
fi
# Left out: the tests of programs not built (gtest's <program>_NOT_BUILT placeholder, or a missing executable), the
# Blender renders, the package and the soak. With --target the tests of those programs are named (-R); without, the
# left-out ones are (-E: one placeholder per program not built keeps it short, where the whole suite's names would
# not fit in one argument).
mapfile -t select < <(ctest --test-dir build-asan --show-only=json-v1 | python3 -c '
import json, os, re, sys
programs = set(sys.argv[1:])
skip = re.compile(r"_NOT_BUILT$|^packaging\.|^soak\.")
def runs(t):
    program = t.get("command") and t["command"][0]
    return (not skip.search(t["name"]) and program and os.path.exists(program) and "blender" not in program
            and (not programs or os.path.basename(program) in programs))
tests = json.load(sys.stdin)["tests"]
names = [t["name"] for t in tests if runs(t) == bool(programs)]
print("-R" if programs else "-E")
print("^(" + "|".join(re.escape(n) for n in names) + ")$" if names else "^$no-test")
' "${targets[@]}")
reports=$(mktemp -d /tmp/colorlab-asan-XXXXXX)
# The test preset's options (CMakePresets.json, `asan`), read from there so the two cannot differ, plus one report file
# per process.
while IFS= read -r line; do export "${line?}"; done < <(python3 -c '
import json, os
preset = next(p for p in json.load(open("CMakePresets.json"))["testPresets"] if p["name"] == "asan")
for name, value in preset["environment"].items():
    print(name + "=" + value.replace("${sourceDir}", os.getcwd()))
')
export ASAN_OPTIONS="$ASAN_OPTIONS:log_path=$reports/report"
export UBSAN_OPTIONS="$UBSAN_OPTIONS:log_path=$reports/report"
status=0
nice -n 19 ctest --test-dir build-asan -L "$labels" "${select[@]}" -j2 --timeout 900 --output-on-failure "$@" ||
  status=$?
if compgen -G "$reports/report*" >/dev/null; then
  echo "asan.sh: sanitizer reports (one file per process):" >&2
  for f in "$reports"/report*; do echo "== $f" >&2; cat "$f" >&2; done
  exit 1
fi
rm -rf "$reports"
echo "asan.sh: no AddressSanitizer, LeakSanitizer or UBSan report"
exit "$status"
