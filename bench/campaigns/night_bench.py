#!/usr/bin/env python3
"""The lab's night on the simulated lab, timed (issue 9).

1. Chart read, time per patch above the simulated device's own time, measured with the campaign:
   chart-read runs at two time scales in the same harness; the time between consecutive patch
   commits is wall(ts) = device/ts + host, so device = (w_a - w_b) / (1/a - 1/b) and host follows.
2. A simulated night: cabinet-grid (80 spots x 3 lamps x 4 dimmer levels), chart-read (140
   patches) and characterize-camera (the SG photographed 25 frames as RAW, TIFF 16/8 and JPEG by the
   full-size simulated DSLR, against that chart-read, every approach fitted) at full size, one after
   the other on one daemon, with where the time goes (lab calls by kind from the journal is not
   exposed, so the split is per campaign and per phase; characterize-camera's phases from the times
   its log lines reach the daemon's stderr).

Usage: bench/campaigns/night_bench.py [--build build] [--night-scale 1000] [--skip-night]
                                      [--skip-chart-scales] [--night grid,chart,camera] [--skip-camera-split]
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from datetime import datetime

import requests


def start_daemon(build, state, scale, log=None):
    """log: a list that receives (monotonic time, line) for every line colorlabd writes to stderr."""
    cfg = os.path.join(state, "colorlabd.toml")
    lab = os.path.join(state, "lab.toml")
    os.makedirs(state, exist_ok=True)
    with open(lab, "w") as f:
        f.write("[genicam]\nenabled = false\n")
    with open(cfg, "w") as f:
        f.write(f"[simulator]\nenabled = true\ntime_scale = {scale}\nconfig = \"{lab}\"\n")
    proc = subprocess.Popen([os.path.join(build, "bin", "colorlabd"), "--config", cfg, "--state",
                             os.path.join(state, "s"), "--listen", "127.0.0.1:0"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE if log is not None else subprocess.DEVNULL,
                            text=True)
    if log is not None:
        def read():
            for line in proc.stderr:
                log.append((time.monotonic(), line.rstrip("\n")))
        threading.Thread(target=read, daemon=True).start()
    endpoint = os.path.join(state, "s", "colorlabd.endpoint")
    for _ in range(400):
        if os.path.exists(endpoint):
            with open(endpoint) as f:
                e = json.load(f)
            proc.simulator_pid = e.get("simulator_pid")
            return proc, e["url"]
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
    r["measurements"] = measurements(url, e["run_id"])
    return wall, r


def measurements(url, run_id):
    """Every page of a run's measurements (the run document itself stays small)."""
    items, cursor = [], None
    while True:
        params = {"limit": 5000}
        if cursor:
            params["cursor"] = cursor
        page = requests.get(url + "/v1/runs/" + run_id + "/measurements", params=params).json()
        items += page["items"]
        cursor = page.get("next_cursor")
        if not cursor:
            return items


def camera_phases(log, t0, t1):
    """characterize-camera's phases between t0 and t1 from its log lines: lamp and operator, photographs,
    then one fit per format."""
    marks = [(t, line.split("characterize-camera: ", 1)[1]) for t, line in log
             if t0 <= t <= t1 and "characterize-camera: " in line]
    phases, last = [], t0
    for t, text in marks:
        if "stable after" in text:
            phases.append(("lamp on, operator requests answered by the simulator, wait_stable (" + text + ")", t - last))
        elif text.startswith("photographed"):
            phases.append(("photograph_chart: " + text + ", averaged, located and sampled", t - last))
        elif " fitted: " in text:
            phases.append(("lab.analysis.characterize " + text, t - last))
        else:
            continue
        last = t
    phases.append(("records and the last commit", t1 - last))
    return phases


def cpu_s(pid):
    """User + system CPU seconds of a process and its threads so far."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def cpu_split(proc):
    return {"colorlabd": cpu_s(proc.pid), "colorlab-sim": cpu_s(proc.simulator_pid) if proc.simulator_pid else 0.0}


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
    ap.add_argument("--skip-chart-scales", action="store_true", help="only the night")
    ap.add_argument("--night", default="grid,chart,camera", help="the night's campaigns, in this order")
    ap.add_argument("--skip-camera-split", action="store_true",
                    help="do not photograph the chart again as RAW only after the night (the split of the camera's time)")
    a = ap.parse_args()
    out = {}
    scales = [float(s) for s in a.scales.split(",")]
    walls = {}
    for scale in ([] if a.skip_chart_scales else scales):
        with tempfile.TemporaryDirectory() as d:
            proc, url = start_daemon(a.build, d, scale)
            try:
                wall, r = run(url, "chart-read", {"confirm_load": False})
                walls[scale] = per_patch(r)
                print(f"chart-read at time scale {scale:g}: {wall:.1f} s, {walls[scale]*1000:.1f} ms per patch", flush=True)
            finally:
                proc.send_signal(signal.SIGKILL)
                proc.wait()
    if not a.skip_chart_scales:
        sa, sb = scales[0], scales[1]
        device = (walls[sa] - walls[sb]) / (1 / sa - 1 / sb)
        host = walls[sa] - device / sa
        out["chart_read"] = {"per_patch_s": walls, "device_s_per_patch": device, "host_s_per_patch": host,
                             "host_over_device_at_scale_1": host / device}
        print(f"device time per patch (time scale 1): {device:.3f} s; colorlab's own time per patch: {host*1000:.1f} ms "
              f"= {100*host/device:.1f} % above the device's own time", flush=True)
    if not a.skip_night:
        night = a.night.split(",")
        with tempfile.TemporaryDirectory() as d:
            log = []
            proc, url = start_daemon(a.build, d, a.night_scale, log)
            try:
                out["night"] = {"time_scale": a.night_scale}
                t0 = time.monotonic()
                if "grid" in night:
                    gw, g = run(url, "cabinet-grid", {})
                    s = g["summary"]["script"]
                    out["night"].update({"cabinet_grid_s": gw, "grid_values": s["grid_values"],
                                         "lamp_warmups": s["lamp_warmups"], "operator_aims": s["operator_aims"]})
                    print(f"cabinet-grid {gw:.1f} s ({s['grid_values']} readings, {s['lamp_warmups']} lamp warm-ups, "
                          f"{s['operator_aims']} aims)", flush=True)
                if "chart" in night or "camera" in night:
                    cw, c = run(url, "chart-read", {})
                    out["night"]["chart_read_s"] = cw
                    print(f"chart-read {cw:.1f} s", flush=True)
                if "camera" in night:
                    # Full size: 25 frames, every format, the SG, the full 3504 x 2336 simulated 20D.
                    t_start, cpu0 = time.monotonic(), cpu_split(proc)
                    kw, k = run(url, "characterize-camera", {"reference_run": c["id"], "frames": 25})
                    phases = camera_phases(log, t_start, time.monotonic())
                    cpu = {k_: v - cpu0[k_] for k_, v in cpu_split(proc).items()}
                    out["night"]["characterize_cpu_s"] = cpu
                    print("characterize-camera CPU: " + ", ".join(f"{k_} {v:.1f} s" for k_, v in cpu.items()), flush=True)
                    r = k["summary"]["script"]
                    cv = {f: {n: ap_["cv"]["mean"] for n, ap_ in v["approaches"].items()} for f, v in r["formats"].items()}
                    out["night"].update({"characterize_camera_s": kw, "characterize_phases_s": phases, "characterize_cv_mean": cv})
                    print(f"characterize-camera {kw:.1f} s", flush=True)
                    for name, secs in phases:
                        print(f"  {secs:7.1f} s  {name}", flush=True)
                    for f, v in cv.items():
                        print(f"  {f}: CV mean dE00 " + ", ".join(f"{n} {x:.2f}" for n, x in sorted(v.items())), flush=True)
                out["night"]["total_s"] = time.monotonic() - t0
                print(f"night at time scale {a.night_scale:g}: total {out['night']['total_s']:.1f} s", flush=True)
                if "camera" in night and not a.skip_camera_split:
                    # Not part of the night: the same photographs as RAW only, to split photograph_chart's time
                    # into the raws (render, DNG, transfer, LibRaw, the frame pipeline's sum) and the camera's
                    # own processed files (rendered, written, read back and averaged) with their locating.
                    t_start, cpu0 = time.monotonic(), cpu_split(proc)
                    rw, _ = run(url, "characterize-camera", {"reference_run": c["id"], "frames": 25, "formats": ["raw"]})
                    raw_phases = camera_phases(log, t_start, time.monotonic())
                    cpu = {k_: v - cpu0[k_] for k_, v in cpu_split(proc).items()}
                    out["camera_raw_only"] = {"wall_s": rw, "phases_s": raw_phases, "cpu_s": cpu}
                    print(f"(apart from the night) characterize-camera, RAW only: {rw:.1f} s; CPU "
                          + ", ".join(f"{k_} {v:.1f} s" for k_, v in cpu.items()), flush=True)
                    for name, secs in raw_phases:
                        print(f"  {secs:7.1f} s  {name}", flush=True)
            finally:
                proc.send_signal(signal.SIGKILL)
                proc.wait()
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    sys.exit(main())
