#!/usr/bin/env bash
# clang-tidy (Debian 12's clang-tidy 14) with the project's .clang-tidy over the compile database of a configured
# build (compile_commands.json; the dev preset writes it). Every finding is an error (WarningsAsErrors), so a
# clean tree exits 0. Slow (minutes per dozen files on 2 cores): a developer's tool, not part of CI.
#   scripts/tidy.sh [REGEX]    only the files whose path matches REGEX (default: every project source outside
#                              tests/ and bench/); COLORLAB_TIDY_JOBS (default 2), COLORLAB_TIDY_BUILD (default build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${COLORLAB_TIDY_BUILD:-build}
jobs=${COLORLAB_TIDY_JOBS:-2}
regex=${1:-"$(pwd)/(core|analysis|drivers|sim|campaigns|daemon|protocol|client|verify|fleet)/.*\\.cpp\$"}
RUN_CLANG_TIDY=${RUN_CLANG_TIDY:-run-clang-tidy}
command -v "$RUN_CLANG_TIDY" >/dev/null || { echo "tidy.sh: $RUN_CLANG_TIDY not found (apt-get install clang-tidy)" >&2; exit 2; }
[[ -f $build/compile_commands.json ]] || { echo "tidy.sh: no $build/compile_commands.json: cmake --preset dev first" >&2; exit 2; }
exec nice -n 19 "$RUN_CLANG_TIDY" -quiet -p "$build" -j "$jobs" "$regex"
