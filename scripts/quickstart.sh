#!/usr/bin/env bash
# Quick start: set up, build, start colorlabd with its embedded simulated lab, run the default
# campaign through the CLI, print the stored result and how to query it again, stop the daemon.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh dev

state="${COLORLAB_STATE:-./colorlab-state}"
listen="${COLORLAB_LISTEN:-127.0.0.1:8765}"
bin=build/bin

mkdir -p "$state"
"$bin/colorlabd" --state "$state" --listen "$listen" 2>>"$state/colorlabd.log" &
daemon=$!
trap 'kill -TERM $daemon 2>/dev/null; wait $daemon 2>/dev/null || true' EXIT

url="http://$listen"
for _ in $(seq 1 100); do
  "$bin/colorlab" --url "$url" status >/dev/null 2>&1 && break
  sleep 0.1
done

"$bin/colorlab" --url "$url" status
"$bin/colorlab" --url "$url" instruments
run_id=$("$bin/colorlab" --url "$url" run luminance-spot --id-only --param readings=3)
"$bin/colorlab" --url "$url" show "$run_id"
cat <<MSG

The reading above is stored in $state/colorlab.db (simulated instruments, flagged as such);
the daemon's log is $state/colorlabd.log.
Query it again while a daemon runs:
  $bin/colorlabd --state $state --listen $listen &
  $bin/colorlab --url $url runs
  $bin/colorlab --url $url show $run_id --json
  curl -s $url/v1/runs/$run_id
MSG
