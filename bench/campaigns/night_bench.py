#!/usr/bin/env python3
"""The lab's night on the simulated lab, timed (issue 9).

1. Chart read, time per patch above the simulated device's own time, measured with the campaign:
   chart-read runs at two time scales in the same harness; the time between consecutive patch
   commits is wall(ts) = device/ts + host, so device = (w_a - w_b) / (1/a - 1/b) and host follows.
2. A simulated night: cabinet-grid (80 spots x 3 lamps x 4 dimmer levels) and chart-read (140
   patches) at full size, one after the other on one daemon, with where the time goes (lab calls
   by kind from the journal is not exposed, so the split is per campaign and per phase).

Usage: bench/campaigns/night_bench.py [--build build] [--night-scale 1000] [--skip-night]
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from datetime import datetime

import requests


def start_daemon(build, state, scale):
    cfg = os.path.join(state, "colorlabd.toml")
    lab = os.path.join(state, "lab.toml")
    os.makedirs(state, exist_ok=True)
    with open(lab, "w") as f:
        f.write("[genicam]\nenabled = false\n")
    with open(cfg, "w") as f:
        f.write(f"[simulator]\nenabled = true\ntime_scale = {scale}\nconfig = \"{lab}\"\n")
    proc = subprocess.Popen([os.path.join(build, "bin", "colorlabd"), "--config", cfg, "--state",
                             os.path.join(state, "s"), "--listen", "127.0.0.1:0"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    endpoint = os.path.join(state, "s", "colorlabd.endpoint")
    for _ in range(400):
        if os.path.exists(endpoint):
            with open(endpoint) as f:
                return proc, json.load(f)["url"]
        time.sleep(0.05)
    proc.kill()
    raise SystemExit("colorlabd did not start")


def run(url, campaign, params):
    t0 = time.monotonic()
    e = requests.post(url + "/v1/executions", json={"campaign": campaign, "params": params}).json()
    while True:
        e = requests.get(url + "/v1/executions/" + e["id"]).json()
        if e["status"] in ("finished_ok", "finished_error", "aborted", "interrupted"):
            break
        time.sleep(0.05)
    wall = time.monotonic() - t0
    if e["status"] != "finished_ok":
        raise SystemExit(f"{campaign}: {e['status']}: {e.get('reason')}")
    r = requests.get(url + "/v1/runs/" + e["run_id"]).json()
    return wall, r


def stamp(m):
    return datetime.fromisoformat(m["measured_at"].replace("Z", "+00:00")).timestamp()


def per_patch(run_json):
    ts = sorted(stamp(m) for m in run_json["measurements"])
    return (ts[-1] - ts[0]) / (len(ts) - 1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--scales", default="10,20")
    ap.add_argument("--night-scale", type=float, default=1000)
    ap.add_argument("--skip-night", action="store_true")
    a = ap.parse_args()
    out = {}
    scales = [float(s) for s in a.scales.split(",")]
    walls = {}
    for scale in scales:
        with tempfile.TemporaryDirectory() as d:
            proc, url = start_daemon(a.build, d, scale)
            try:
                wall, r = run(url, "chart-read", {"confirm_load": False})
                walls[scale] = per_patch(r)
                print(f"chart-read at time scale {scale:g}: {wall:.1f} s, {walls[scale]*1000:.1f} ms per patch", flush=True)
            finally:
                proc.send_signal(signal.SIGKILL)
                proc.wait()
    sa, sb = scales[0], scales[1]
    device = (walls[sa] - walls[sb]) / (1 / sa - 1 / sb)
    host = walls[sa] - device / sa
    out["chart_read"] = {"per_patch_s": walls, "device_s_per_patch": device, "host_s_per_patch": host,
                         "host_over_device_at_scale_1": host / device}
    print(f"device time per patch (time scale 1): {device:.3f} s; colorlab's own time per patch: {host*1000:.1f} ms "
          f"= {100*host/device:.1f} % above the device's own time", flush=True)
    if not a.skip_night:
        with tempfile.TemporaryDirectory() as d:
            proc, url = start_daemon(a.build, d, a.night_scale)
            try:
                t0 = time.monotonic()
                gw, g = run(url, "cabinet-grid", {})
                cw, c = run(url, "chart-read", {})
                total = time.monotonic() - t0
                s = g["summary"]["script"]
                out["night"] = {"time_scale": a.night_scale, "cabinet_grid_s": gw, "chart_read_s": cw, "total_s": total,
                                "grid_values": s["grid_values"], "lamp_warmups": s["lamp_warmups"],
                                "operator_aims": s["operator_aims"]}
                print(f"night at time scale {a.night_scale:g}: cabinet-grid {gw:.1f} s ({s['grid_values']} readings, "
                      f"{s['lamp_warmups']} lamp warm-ups, {s['operator_aims']} aims), chart-read {cw:.1f} s, "
                      f"total {total:.1f} s", flush=True)
            finally:
                proc.send_signal(signal.SIGKILL)
                proc.wait()
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    sys.exit(main())
