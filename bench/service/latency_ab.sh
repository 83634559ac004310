#!/bin/sh
# latency_probe.py with the steps' commits on the io thread (A: COLORLAB_BENCH_COMMIT_ON_IO_THREAD=1, as before
# the committer thread) and on the committer thread (B: as shipped), alternately A B A B … with the same binary,
# in one run (issue 27). Each pass is a whole probe: idle, then the dissertation study. Writes OUT/A1.json,
# OUT/B1.json, … (the probe's --json) and OUT/A1.log … (the daemon's log, with the io-thread lines of
# COLORLAB_IO_LAG_MS=5), then prints one line per pass and route: the study phase's n, p50, p99 and max (ms).
# With AB=priority the switch is colorlabd's CPU priority of its heavy work instead (docs/configuration.md, "CPU
# priority"): A `--priority 0 0` (everything at colorlabd's own priority, colorlabd's default), B `--priority 10 10`; the
# commits on the committer thread in both.
# Usage: [AB=commit|priority] bench/service/latency_ab.sh BUILD OUT [PASSES] [IDLE_S]
set -eu
build=$1 out=$2 passes=${3:-2} idle=${4:-20}
ab=${AB:-commit}
here=$(dirname "$0")
mkdir -p "$out"
i=1
while [ "$i" -le "$passes" ]; do
  for side in A B; do
    on_io=0 priority=
    if [ "$ab" = priority ]; then
      if [ "$side" = A ]; then priority="--priority 0 0"; else priority="--priority 10 10"; fi
    else
      [ "$side" = A ] && on_io=1
    fi
    # $priority unquoted on purpose: empty, or two arguments.
    # shellcheck disable=SC2086
    COLORLAB_BENCH_COMMIT_ON_IO_THREAD=$on_io COLORLAB_IO_LAG_MS=5 python3 "$here/latency_probe.py" --build "$build" \
      --idle-s "$idle" --json "$out/$side$i.json" --log "$out/$side$i.log" $priority > "$out/$side$i.txt" || true
  done
  i=$((i + 1))
done
python3 - "$out" <<'PY'
import glob, json, os, sys
for path in sorted(glob.glob(os.path.join(sys.argv[1], "[AB]*.json")), key=lambda p: (p[-6:-5], p)):
    d = json.load(open(path))
    name = os.path.basename(path)[:-5]
    for phase in d["phases"]:
        worst = max(r["max"] for r in phase["routes"].values())
        slow = phase["slow_answers"]
        parts = ", ".join(f"{k} {v:.0f}" for k, v in slow["ms_by_part"].items() if v >= 0.5)
        print(f"{name} {phase['phase']:5s} load {phase['load_before'][0]:5.2f}->{phase['load_after'][0]:5.2f} "
              f"slowest {worst:7.1f} ms; {slow['answers']} answers > 50 ms, ms by part: {parts or '-'}")
        for route, r in phase["routes"].items():
            print(f"   {route:34s} {r['n']:6d} {r['p50']:7.1f} {r['p99']:7.1f} {r['max']:7.1f}")
PY
