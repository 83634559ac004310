#!/usr/bin/env python3
"""Resume after kill -9 to the next measurement, measured on the simulated lab at time scale 1.

For each trial: start colorlabd (embedded simulated lab), run luminance-spot, kill -9 it after
three readings, start it again and time from the restart (exec) to the commit of the first new
reading. The same run's own reading interval (median gap between consecutive readings, the
LS-110's measuring time) is reported beside it, so the engine's part is the difference. Target
(issue 8): ≤ 2 s plus the instruments' own settle time.

usage: bench/campaigns/resume_latency.py [build/bin] [trials]
"""
import json, os, signal, statistics, subprocess, sys, tempfile, time, urllib.request
from datetime import datetime

BIN = sys.argv[1] if len(sys.argv) > 1 else "build/bin"
TRIALS = int(sys.argv[2]) if len(sys.argv) > 2 else 5


def start(state):
    log = open(os.path.join(os.path.dirname(state), "colorlabd.log"), "a")
    p = subprocess.Popen([os.path.join(BIN, "colorlabd"), "--state", state, "--listen", "127.0.0.1:0"], stderr=log)
    endpoint = os.path.join(state, "colorlabd.endpoint")
    for _ in range(2000):
        try:
            with open(endpoint) as f:
                e = json.load(f)
            if e["pid"] == p.pid:
                return p, e["url"]
        except (OSError, ValueError):
            pass
        time.sleep(0.005)
    raise RuntimeError("colorlabd did not start")


def get(url, path):
    with urllib.request.urlopen(url + path, timeout=30) as r:
        return json.load(r)


def post(url, path, body):
    req = urllib.request.Request(url + path, data=json.dumps(body).encode(), headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=30) as r:
        return json.load(r)


def stamp(iso):
    return datetime.fromisoformat(iso.replace("Z", "+00:00")).timestamp()


resume, interval = [], []
for trial in range(TRIALS):
    with tempfile.TemporaryDirectory() as tmp:
        state = os.path.join(tmp, "state")
        p, url = start(state)
        e = post(url, "/v1/executions", {"campaign": "luminance-spot", "params": {"readings": 30}})
        while len(get(url, "/v1/runs/" + e["run_id"] + "/measurements?limit=5000")["items"]) < 3:
            time.sleep(0.01)
        p.send_signal(signal.SIGKILL)
        p.wait()
        time.sleep(0.3)  # let the simulated lab's child go (it holds the GigE Vision port)
        t0 = time.time()
        p, url = start(state)
        while True:
            ms = get(url, "/v1/runs/" + e["run_id"] + "/measurements?limit=5000")["items"]
            fresh = [m for m in ms if stamp(m["measured_at"]) > t0]
            if fresh:
                break
            time.sleep(0.005)
        resume.append(stamp(fresh[0]["measured_at"]) - t0)
        times = [stamp(m["measured_at"]) for m in ms]
        gaps = [b - a for a, b in zip(times, times[1:]) if a > t0 or b < t0 - 0.3]
        interval.append(statistics.median(gaps) if gaps else float("nan"))
        p.send_signal(signal.SIGKILL)
        p.wait()
        time.sleep(0.3)

print(f"trials: {TRIALS}")
print(f"restart to next committed reading: median {statistics.median(resume):.3f} s, max {max(resume):.3f} s")
print(f"one LS-110 reading (same runs):     median {statistics.median(interval):.3f} s")
print(f"engine's part (difference):         median {statistics.median(resume) - statistics.median(interval):.3f} s")
