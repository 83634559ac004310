#!/usr/bin/env bash
# Quick start: set up, build, start colorlabd with its embedded simulated lab, run the dissertation study (its
# campaigns through the night queue, then the report), print the report's path and how to open it and query the
# runs again, stop the daemon.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh dev

state="${COLORLAB_STATE:-./colorlab-state}"
listen="${COLORLAB_LISTEN:-127.0.0.1:8765}"
# Lab seconds per wall second. The study is about 3 lab hours (the 8 × 10 grid under three lamps at four levels is
# most of it); at 50 it takes about 5 minutes on two cores, and the lamps' warm-up, the LS-110's drift windows
# (5 lab s = 0.1 s apart) and the settling keep their physics (docs/reports.md, "The dissertation study").
time_scale="${COLORLAB_TIME_SCALE:-50}"
bin=build/bin

mkdir -p "$state"
# The embedded simulated lab, time-scaled: the daemon's configuration, kept in the state directory.
cat >"$state/quickstart.toml" <<TOML
# written by scripts/quickstart.sh
[simulator]
enabled = true
time_scale = $time_scale
seed = 1
TOML
"$bin/colorlabd" --config "$state/quickstart.toml" --state "$state" --listen "$listen" 2>>"$state/colorlabd.log" &
daemon=$!
trap 'kill -TERM $daemon 2>/dev/null; wait $daemon 2>/dev/null || true' EXIT

url="http://$listen"
for _ in $(seq 1 100); do
  "$bin/colorlab" --url "$url" status >/dev/null 2>&1 && [[ -S "$state/colorlabd.sock" ]] && break
  sleep 0.1
done

"$bin/colorlab" --url "$url" status
"$bin/colorlab" --url "$url" instruments
# The study: the daemon's sequence `dissertation` (chart-read, frame-average, cabinet-grid, floor-luminance,
# characterize-camera, dimmer-exposure) queued as one group of the night queue, followed by the event stream, then
# the report. Over the Unix socket (control needs no key there); its last line is the report.
report="$state/dissertation-report.html"
"$bin/colorlab" --socket "$state/colorlabd.sock" study dissertation \
  --state-file "$state/dissertation-study.json" -o "$report" | tee "$state/dissertation-study.log"
report=$(tail -n 1 "$state/dissertation-study.log")
cat <<MSG

The study's runs are stored in $state/colorlab.db (simulated instruments, flagged as such); the daemon's log is
$state/colorlabd.log, the study's $state/dissertation-study.log.
Open the report:
  xdg-open $report        # or any browser: one self-contained HTML file
Query it again while a daemon runs:
  $bin/colorlabd --state $state --listen $listen &
  $bin/colorlab --url $url runs
  $bin/colorlab --url $url show RUN_ID --json
  $bin/colorlab --url $url report RUN_ID… -o report.html
$report
MSG
