#!/usr/bin/env python3
"""Turns an strace log of ArgyllCMS chartread on the simulated SpectroScan T into phase times.

The log comes from tests/sim/conformance/argyll_driver.py --trace (strace -f -ttt -T on openat, read,
write, close). Every byte chartread exchanges with the serial port is in it with the wall time the
call started plus the time spent inside it, so the moment an answer was complete is start + duration.

Phases (seconds, wall clock):
  init       first open of the port .. the "place sheet" prompt (detection, identification, table init)
  locate     that prompt .. the table back online after the last sight reading (D0 05 01); the
             harness answers prompts at once, so this is the device's share of locating
  calibrate  .. the first D0 07 MoveAndMeasure (white calibration on the tile, parameters)
  patches    first D0 07 sent .. last patch's answers complete; per patch: D0 07 and BA 09 04
             round trips and the host's gaps between commands, plus any recalibration (22 09 07)
Prints one JSON object.
"""
import argparse
import json
import re
import sys

LINE = re.compile(r'^(?:\d+\s+)?(?P<t>\d+\.\d+)\s+(?P<call>openat|read|write|close)\((?P<args>.*)\)\s+=\s+'
                  r'(?P<ret>-?\d+)(?:\s+\S+\s+\(.*?\))?(?:\s+<(?P<dur>\d+\.\d+)>)?\s*$')
FIRST_ARG = re.compile(r'^(-?\d+|AT_FDCWD),\s*"(?P<data>(?:[^"\\]|\\.)*)"')
CLOSE_ARG = re.compile(r'^(\d+)$')


def calls(path, port):
    """(start, end, kind, text) for every read/write on the port; kind 'w', 'r', or 'out' (stdout)."""
    tty_fds = set()
    for line in open(path, errors="replace"):
        m = LINE.match(line.strip())
        if not m:
            continue
        t, dur, call, args, ret = float(m["t"]), float(m["dur"] or 0), m["call"], m["args"], int(m["ret"])
        if call == "openat":
            if '"%s"' % port in args and ret >= 0:
                tty_fds.add(ret)
            continue
        if call == "close":
            c = CLOSE_ARG.match(args.strip())
            if c:
                tty_fds.discard(int(c.group(1)))
            continue
        a = FIRST_ARG.match(args)
        if not a or ret <= 0:
            continue
        fd = int(a.group(1))
        data = a["data"].replace("\\r", "").replace("\\n", "")
        if fd in tty_fds:
            yield t, t + dur, "w" if call == "write" else "r", data
        elif fd == 1 and call == "write":
            yield t, t + dur, "out", data


def timeline(path, port, patches):
    ev = list(calls(path, port))
    port_ev = [e for e in ev if e[2] in ("w", "r")]
    if not port_ev:
        raise SystemExit("no traffic on %s in %s" % (port, path))
    t_open = next(e[0] for e in port_ev)
    sheet = next((e[0] for e in ev if e[2] == "out" and "place sheet" in e[3]), None)
    sights = [i for i, e in enumerate(ev) if e[2] == "w" and e[3].startswith(";D00501")]
    measures = [i for i, e in enumerate(ev) if e[2] == "w" and e[3].startswith(";D007")]
    if sheet is None or not sights or len(measures) < patches:
        raise SystemExit("trace does not show a complete chart read (%d D0 07 of %d)" % (len(measures), patches))
    # Table back online (D0 10) after the last sight reading ends the location.
    online = next(i for i in range(sights[-1] + 1, len(ev)) if ev[i][2] == "w" and ev[i][3].startswith(";D010"))
    located = next(e[1] for e in ev[online + 1:] if e[2] == "r")
    first_measure = ev[measures[0]][0]

    def last_answer_before(k):
        """End of the last port read between event index k and the next D0 07 (or the end of reading)."""
        end = None
        for e in ev[k + 1:]:
            if e[2] == "w" and e[3].startswith(";D007"):
                break
            if e[2] == "out" and "read OK" in e[3]:
                break
            if e[2] == "r":
                end = e[1]
        return end

    per_patch = []
    for n, i in enumerate(measures[:patches]):
        w = ev[i]
        answer = next(e for e in ev[i + 1:] if e[2] == "r")
        done = last_answer_before(i)
        nxt = ev[measures[n + 1]][0] if n + 1 < len(measures) else done
        window = [e for e in ev if w[0] <= e[0] < nxt and e[2] in ("w", "r")]
        in_commands, writes = 0.0, 0
        pending = None
        for e in window:
            if e[2] == "w":
                pending = e[0]
                writes += 1
            elif pending is not None:
                in_commands += e[1] - pending
                pending = None
        # Time spent inside read() is Argyll's VMIN=64/VTIME=1 wait: a short answer is handed over
        # only after 0.1 s of silence on the line.
        read_wait = sum(e[1] - e[0] for e in window if e[2] == "r")
        per_patch.append({"start": w[0], "measure_answer": answer[1] - w[0], "done": done, "read_wait": read_wait,
                          "cycle": nxt - w[0], "commands": writes, "in_commands": in_commands,
                          "host_gaps": (nxt - w[0]) - in_commands,
                          "recalibrated": any(e[3].startswith(";220907") for e in window if e[2] == "w")})
    last_done = per_patch[-1]["done"]

    def split(t0, t1):
        """Waiting for answers (request sent .. answer handed over) vs the host's own gaps, and the share
        of the waiting spent inside read() on VTIME."""
        in_commands, read_wait, pending = 0.0, 0.0, None
        for e in port_ev:
            if not t0 <= e[0] < t1:
                continue
            if e[2] == "w":
                pending = e[0]
            elif pending is not None:
                in_commands += e[1] - pending
                read_wait += e[1] - e[0]
                pending = None
        return {"waiting_for_device": in_commands, "read_wait": read_wait, "host_gaps": (t1 - t0) - in_commands}
    writes = [e for e in port_ev if e[2] == "w"]
    return {
        "t_open": t_open,
        "init_s": sheet - t_open,
        "locate_s": located - sheet,
        "calibrate_s": first_measure - located,
        "patches_s": last_done - first_measure,
        "total_s": last_done - t_open,
        "patches": len(per_patch),
        "calibrations": sum(1 for e in writes if e[3].startswith(";220907") and e[0] <= last_done),
        "commands_to_last_patch": sum(1 for e in writes if e[0] <= last_done),
        "init_split": split(t_open, sheet),
        "calibrate_split": split(located, first_measure),
        "per_patch": per_patch,
    }


def main():
    p = argparse.ArgumentParser()
    p.add_argument("trace")
    p.add_argument("--port", default="/dev/ttyS7")
    p.add_argument("--patches", type=int, required=True)
    a = p.parse_args()
    json.dump(timeline(a.trace, a.port, a.patches), sys.stdout)
    print()


if __name__ == "__main__":
    main()
