#!/usr/bin/env python3
"""The API's answer times through a night's work, beside the same probe with nothing running (issue 27).

One colorlabd with its embedded simulated lab (time-scaled like scripts/quickstart.sh). Two phases on it, in
one run:

1. idle: no campaign; the probe runs for --idle-s seconds.
2. busy: the dissertation study queued as one group (chart-read, frame-average, cabinet-grid, floor-luminance,
   characterize-camera at full size, dimmer-exposure) and the probe runs until the group has ended.

The probe in each phase: two clients, each polling every 20 ms, in turn, GET /v1, /v1/instruments, /v1/runs,
/v1/runs/{id} (the newest run), /v1/control and /v1/queue; a third client, every 20 ms, answers an operator request and pauses and
resumes an execution (POST /v1/requests/{id}, /v1/executions/{id}/pause, /resume). Any unfinished execution
holds the night's queue, so these go to `probe-ask` (a campaign of this probe's, touching no instrument, run
once before the phases and answered): its request is no longer open (404) and it has ended (409). The same
handlers on the same main thread find and refuse them: what they measure is the wait behind other work there. Every answer's time is from the request sent to the whole answer read.

Reports per route and phase: count, p50, p99 and the slowest answer (ms), and the machine's load average.
Target (issue 27): the slowest answer of every route <= 50 ms in the busy phase.

Usage: bench/service/latency_probe.py [--build build] [--time-scale 50] [--idle-s 60] [--json out.json]
Run it niced when the machine is shared: nice -n 10 python3 bench/service/latency_probe.py
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

import requests

PROBE_ASK = """
return {
  description = "latency_probe: asks the operator until told to stop (touches no instrument)",
  needs = {},
  parameters = {},
  run = function(p)
    local n = 0
    while true do
      local a = lab.operator.request { action = "probe_answer", prompt = "answer me", options = { "again", "stop" },
                                       default = "stop", timeout_s = 604800 }
      n = n + 1
      if a.answer == "stop" then break end
    end
    return { answered = n }
  end,
}
"""

READ_ROUTES = ["/v1", "/v1/instruments", "/v1/runs", "/v1/runs/{id}", "/v1/control", "/v1/queue"]
TERMINAL = ("finished_ok", "finished_error", "aborted", "interrupted")


def start_daemon(build, state, scale, log_path=None):
    os.makedirs(os.path.join(state, "s", "campaigns"), exist_ok=True)
    with open(os.path.join(state, "s", "campaigns", "probe-ask.lua"), "w") as f:
        f.write(PROBE_ASK)
    cfg = os.path.join(state, "colorlabd.toml")
    with open(cfg, "w") as f:
        # The probe's clients start, answer, pause and resume over loopback TCP, as a lab's own console would.
        f.write(f"[simulator]\nenabled = true\ntime_scale = {scale}\nseed = 1\n[access]\nloopback_scope = \"control\"\n")
    log = open(log_path or os.path.join(state, "colorlabd.log"), "w")
    proc = subprocess.Popen([os.path.join(build, "bin", "colorlabd"), "--config", cfg, "--state",
                             os.path.join(state, "s"), "--listen", "127.0.0.1:0"],
                            stdout=subprocess.DEVNULL, stderr=log)
    endpoint = os.path.join(state, "s", "colorlabd.endpoint")
    for _ in range(600):
        if os.path.exists(endpoint):
            with open(endpoint) as f:
                e = json.load(f)
            if e.get("pid") == proc.pid:
                return proc, e["url"]
        time.sleep(0.05)
    proc.kill()
    raise SystemExit("colorlabd did not start; see " + log.name)


class Times:
    def __init__(self):
        self.lock = threading.Lock()
        self.by_route = {}
        self.errors = {}

    def add(self, route, ms, status):
        with self.lock:
            self.by_route.setdefault(route, []).append(ms)
            if status >= 500 or status == 0:
                self.errors[route] = self.errors.get(route, 0) + 1


def timed(session, times, route, method, url, **kw):
    t0 = time.perf_counter()
    try:
        r = session.request(method, url, timeout=30, **kw)
        _ = r.content
        status = r.status_code
    except requests.RequestException:
        r, status = None, 0
    times.add(route, (time.perf_counter() - t0) * 1000.0, status)
    return r


def reader(url, times, stop, run_id):
    s = requests.Session()
    while not stop.is_set():
        for route in READ_ROUTES:
            if stop.is_set():
                break
            path = route.replace("{id}", run_id[0]) if "{id}" in route else route
            if "{id}" in route and not run_id[0]:
                continue
            r = timed(s, times, route, "GET", url + path)
            if route == "/v1/runs" and r is not None and r.ok:
                items = r.json().get("items", [])
                if items:
                    run_id[0] = items[0]["id"]
            time.sleep(0.02)


def operator(url, times, stop, ended_id):
    """Operator answers, pause and resume, on the main thread's handlers. Any unfinished execution holds the
    night's queue, so none is kept waiting beside the study: the answer goes to a request that is no longer
    open (404) and pause/resume to an ended execution (409) — the same routes, found and refused on the main
    thread, which is where they would wait behind heavy work."""
    session = requests.Session()
    while not stop.is_set():
        timed(session, times, "POST /v1/requests/{id}", "POST", url + "/v1/requests/" + ended_id[1], json={"answer": "go"})
        timed(session, times, "POST /v1/executions/{id}/pause", "POST", url + f"/v1/executions/{ended_id[0]}/pause",
              json={})
        timed(session, times, "POST /v1/executions/{id}/resume", "POST", url + f"/v1/executions/{ended_id[0]}/resume",
              json={})
        time.sleep(0.02)


def answered_execution(url):
    """probe-ask run once and answered: (its execution id, its request id), both ended."""
    session = requests.Session()
    e = session.post(url + "/v1/executions", json={"campaign": "probe-ask", "params": {}}).json()
    for _ in range(2000):
        items = [i for i in session.get(url + "/v1/requests").json().get("items", []) if i.get("execution_id") == e["id"]]
        if items:
            session.post(url + "/v1/requests/" + items[0]["id"], json={"answer": "stop"})
            break
        time.sleep(0.02)
    for _ in range(2000):
        if session.get(url + f"/v1/executions/{e['id']}").json()["status"] in TERMINAL:
            return e["id"], items[0]["id"]
        time.sleep(0.02)
    raise SystemExit("probe-ask did not end")


def probe(url, until, label, ended_id):
    times = Times()
    stop = threading.Event()
    run_id = [""]
    threads = [threading.Thread(target=reader, args=(url, times, stop, run_id)) for _ in range(2)]
    threads.append(threading.Thread(target=operator, args=(url, times, stop, ended_id)))
    load0 = os.getloadavg()
    t0 = time.monotonic()
    for t in threads:
        t.start()
    try:
        until()
    finally:
        stop.set()
        for t in threads:
            t.join()
    return {"phase": label, "wall_s": time.monotonic() - t0, "load_before": load0, "load_after": os.getloadavg(),
            "routes": summarize(times), "errors": times.errors}


def summarize(times):
    out = {}
    for route, ms in sorted(times.by_route.items()):
        ms = sorted(ms)
        p = lambda q: ms[min(len(ms) - 1, int(q * len(ms)))]
        out[route] = {"n": len(ms), "p50": p(0.50), "p99": p(0.99), "max": ms[-1]}
    return out


def run_study(url):
    session = requests.Session()
    g = session.post(url + "/v1/queue", json={"sequence": "dissertation", "start": True})
    if not g.ok:
        raise SystemExit("the study was not queued: " + g.text)
    gid = g.json()["id"]
    t0 = time.monotonic()
    while True:
        st = session.get(url + f"/v1/queue/groups/{gid}").json()
        if st["state"] in ("done", "failed"):
            print(f"study {st['state']} in {time.monotonic() - t0:.0f} s", flush=True)
            return st
        time.sleep(1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--time-scale", type=float, default=50)
    ap.add_argument("--idle-s", type=float, default=60)
    ap.add_argument("--json", help="write the figures here too")
    ap.add_argument("--log", help="keep the daemon's log here (its io-thread lines attribute slow answers: "
                                  "COLORLAB_IO_LAG_MS=5 in the environment adds the lag monitor's)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="latency-probe-") as state:
        proc, url = start_daemon(a.build, state, a.time_scale, a.log)
        try:
            ended = answered_execution(url)
            idle = probe(url, lambda: time.sleep(a.idle_s), "idle", ended)
            study = {}
            busy = probe(url, lambda: study.update(run_study(url)), "study", ended)
        finally:
            proc.terminate()
            proc.wait(timeout=60)
    result = {"time_scale": a.time_scale, "phases": [idle, busy], "study_state": study.get("state"),
              "cpus": os.cpu_count()}
    for phase in (idle, busy):
        print(f"\n{phase['phase']}: {phase['wall_s']:.0f} s, load average {phase['load_before'][0]:.2f} -> "
              f"{phase['load_after'][0]:.2f}")
        print(f"  {'route':34s} {'n':>6s} {'p50 ms':>8s} {'p99 ms':>8s} {'max ms':>8s}")
        for route, r in phase["routes"].items():
            print(f"  {route:34s} {r['n']:6d} {r['p50']:8.1f} {r['p99']:8.1f} {r['max']:8.1f}")
        if phase["errors"]:
            print("  errors (5xx or no answer): " + json.dumps(phase["errors"]))
    worst = max(r["max"] for r in busy["routes"].values())
    print(f"\nslowest answer through the study: {worst:.1f} ms (target <= 50 ms): {'met' if worst <= 50 else 'MISSED'}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1)
    return 0 if study.get("state") == "done" else 1


if __name__ == "__main__":
    sys.exit(main())
