#!/bin/sh
# Two builds of colorlabd under the same small-GET load, alternately A B A B … in one run (issue 24: the route
# table against the commit before it). Each pass starts that build's daemon and measures api_load.py's small GETs,
# idle and while a campaign commits. Prints one JSON document per pass, prefixed by its build.
# Usage: bench/service/api_ab.sh BUILD_A BUILD_B [PASSES] [SECONDS]
set -eu
a=$1 b=$2 passes=${3:-2} seconds=${4:-5}
here=$(dirname "$0")
i=0
while [ "$i" -lt "$passes" ]; do
  for build in "$a" "$b"; do
    printf '%s ' "$build"
    python3 "$here/api_load.py" --build "$build" --seconds "$seconds" --rounds 1 --parts small_gets | tr -d '\n '
    echo
  done
  i=$((i + 1))
done
