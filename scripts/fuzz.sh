#!/usr/bin/env bash
# Builds the libFuzzer targets (cmake --preset fuzz: clang 14, ASan + UBSan, build-fuzz/) and runs each
# for a bounded time, starting from a copy of its seed corpus and past crashes (the tree stays clean),
# as many at once as there are cores. Fails on any crash, sanitizer report, leak, timeout or
# out-of-memory, and keeps the input that did it in build-fuzz/fuzz/artifacts/. Installs nothing:
# scripts/setup.sh installs clang and libFuzzer.
#   scripts/fuzz.sh [TARGET...]      COLORLAB_FUZZ_SECONDS (per target, default 10), COLORLAB_FUZZ_JOBS
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

seconds=${COLORLAB_FUZZ_SECONDS:-10}
jobs=${COLORLAB_FUZZ_JOBS:-$(nproc)}
start=$SECONDS

if [[ ! -f build-fuzz/CMakeCache.txt ]]; then
  cmake --preset fuzz >/dev/null
fi
cmake --build --preset fuzz -j "$jobs"
built=$((SECONDS - start))

bin=$root/build-fuzz/fuzz
if (($#)); then
  targets=("$@")
else
  mapfile -t targets < <(ls "$bin" | sed -n 's/_fuzz$//p' | sort)
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$bin/artifacts"

run_one() {
  local t=$1 corpus=$work/$t
  mkdir -p "$corpus"
  for d in corpus regressions; do
    if [[ -d $root/tests/fuzz/$d/$t ]]; then cp "$root/tests/fuzz/$d/$t"/* "$corpus/"; fi
  done
  local args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=1024 -malloc_limit_mb=512 -print_final_stats=1
              -artifact_prefix="$work/$t-")
  if [[ -f $root/tests/fuzz/dict/$t.dict ]]; then args+=(-dict="$root/tests/fuzz/dict/$t.dict"); fi
  local rc=0
  (cd "$work" && "$bin/${t}_fuzz" "${args[@]}" "$corpus") >"$work/$t.log" 2>&1 || rc=$?
  echo "$rc" >"$work/$t.rc"
}

for t in "${targets[@]}"; do
  while (($(jobs -rp | wc -l) >= jobs)); do wait -n || true; done
  run_one "$t" &
done
wait

failed=()
printf '%-18s %12s %10s %s\n' target executions "per s" result
for t in "${targets[@]}"; do
  rc=$(cat "$work/$t.rc" 2>/dev/null || echo "?")
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$t.log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/$t.log")
  if [[ $rc == 0 ]]; then
    printf '%-18s %12s %10s %s\n' "$t" "${runs:-?}" "${rate:-?}" ok
    continue
  fi
  printf '%-18s %12s %10s %s\n' "$t" "${runs:-?}" "${rate:-?}" "FAILED (exit $rc)"
  failed+=("$t")
  for a in "$work/$t"-*; do
    if [[ -e $a ]]; then
      cp "$a" "$bin/artifacts/"
      echo "  input kept: $bin/artifacts/$(basename "$a")"
    fi
  done
  grep -E 'ERROR|SUMMARY|fuzz:|runtime error|Assertion' "$work/$t.log" | head -20 | sed 's/^/  /' || true
done

echo "fuzz: ${#targets[@]} targets × ${seconds} s, ${jobs} at a time; build ${built} s, total $((SECONDS - start)) s"
if ((${#failed[@]})); then
  echo "fuzz: crashes in ${failed[*]} (reproduce: $bin/<target>_fuzz $bin/artifacts/<file>)"
  exit 1
fi
