#!/usr/bin/env python3
"""The data service under load (issue 10), side by side in one run, interleaved:

1. small GETs (`GET /v1/runs/{id}` of a luminance-spot run) with 32 connections, by wrk, while a campaign commits
   measurements and while nothing runs — alternating, several rounds;
2. one 50 MB blob served by colorlabd and by nginx (Debian nginx-light, sendfile on) from the same file on the same
   machine, alternating, by wrk with 4 connections: throughput ratio;
3. 500 idle connections held open: colorlabd's resident memory before and with them.

Usage: python3 bench/service/api_load.py --build build [--seconds 10] [--rounds 3] [--parts small_gets,blob,idle]
Prints one JSON document; docs/PERFORMANCE.md records the figures and this command. `--parts small_gets` alone,
run alternately against two builds, compares two versions of the daemon (bench/service/api_ab.sh).
"""
import argparse
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import tempfile
import time

import requests


def start_daemon(build, state, scale):
    cfg = os.path.join(state, "colorlabd.toml")
    lab = os.path.join(state, "lab.toml")
    os.makedirs(state, exist_ok=True)
    with open(lab, "w") as f:
        f.write("[genicam]\nenabled = false\n")
    with open(cfg, "w") as f:
        # The bench drives campaigns over loopback TCP, as the bench's own user would with a key.
        f.write(f"[access]\nloopback_scope = \"control\"\n\n"
                f"[simulator]\nenabled = true\ntime_scale = {scale}\nconfig = \"{lab}\"\n")
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


def wrk(url, connections, seconds, threads=2):
    out = subprocess.run(["wrk", f"-t{threads}", f"-c{connections}", f"-d{seconds}s", "--latency", url],
                         capture_output=True, text=True, check=True).stdout
    rps = float(re.search(r"Requests/sec:\s+([\d.]+)", out).group(1))
    transfer = re.search(r"Transfer/sec:\s+([\d.]+)(\w+)", out)
    scale = {"B": 1, "KB": 1e3, "MB": 1e6, "GB": 1e9}[transfer.group(2)]
    p99 = re.search(r"99%\s+([\d.]+)(us|ms|s)", out)
    p99_ms = float(p99.group(1)) * {"us": 1e-3, "ms": 1.0, "s": 1e3}[p99.group(2)]
    errors = re.search(r"Non-2xx or 3xx responses:\s+(\d+)", out)
    return {"requests_per_s": rps, "p99_ms": p99_ms, "bytes_per_s": float(transfer.group(1)) * scale,
            "non_2xx": int(errors.group(1)) if errors else 0}


def rss_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        return int(re.search(r"VmRSS:\s+(\d+)", f.read()).group(1))


def start_campaign(url, readings):
    e = requests.post(url + "/v1/executions", json={"campaign": "luminance-spot", "params": {"readings": readings}})
    e.raise_for_status()
    return e.json()


def wait_done(url, execution_id):
    while True:
        e = requests.get(url + "/v1/executions/" + execution_id).json()
        if e["status"] in ("finished_ok", "finished_error", "aborted", "interrupted"):
            return e
        time.sleep(0.1)


def measurements_committed(url, run_id):
    return requests.get(url + "/v1/runs/" + run_id).json()["measurement_count"]


def small_gets(url, seconds, rounds):
    """Interleaved: idle, busy, idle, busy, … on the same run document."""
    first = start_campaign(url, 5)
    wait_done(url, first["id"])
    SMALL_RUN.append(first["run_id"])
    target = url + "/v1/runs/" + first["run_id"]
    idle, busy = [], []
    for _ in range(rounds):
        idle.append(wrk(target, 32, seconds))
        e = start_campaign(url, 1000)
        before = measurements_committed(url, e["run_id"])
        t0 = time.monotonic()
        busy_round = wrk(target, 32, seconds)
        committed = measurements_committed(url, e["run_id"]) - before
        busy_round["commits_per_s_meanwhile"] = committed / (time.monotonic() - t0)
        busy.append(busy_round)
        requests.post(url + "/v1/executions/" + e["id"] + "/abort")
        wait_done(url, e["id"])
    return {"idle": idle, "while_committing": busy}


def nginx_for(directory, port, work):
    conf = os.path.join(work, "nginx.conf")
    with open(conf, "w") as f:
        f.write(f"""daemon off;
master_process off;
worker_processes 1;
error_log {work}/error.log;
pid {work}/nginx.pid;
events {{ worker_connections 1024; }}
http {{
  access_log off;
  sendfile on;
  tcp_nopush on;
  client_body_temp_path {work}/body;
  proxy_temp_path {work}/proxy;
  fastcgi_temp_path {work}/fastcgi;
  uwsgi_temp_path {work}/uwsgi;
  scgi_temp_path {work}/scgi;
  server {{
    listen 127.0.0.1:{port};
    root {directory};
  }}
}}
""")
    proc = subprocess.Popen(["nginx", "-c", conf, "-p", work], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for _ in range(100):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.1).close()
            return proc
        except OSError:
            time.sleep(0.05)
    proc.kill()
    raise SystemExit("nginx did not start")


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def blob_throughput(url, state, run_id, seconds, rounds, work):
    """A 50 MB blob through colorlabd's blob route and through nginx, alternating."""
    sha, path = put_blob(state, run_id, 50 * 1000 * 1000)
    served = os.path.join(work, "www")
    os.makedirs(served, exist_ok=True)
    shutil.copyfile(path, os.path.join(served, "blob.bin"))
    port = free_port()
    nginx = nginx_for(served, port, work)
    try:
        ours, theirs = [], []
        for _ in range(rounds):
            ours.append(wrk(url + "/v1/blobs/" + sha, 4, seconds)["bytes_per_s"])
            theirs.append(wrk(f"http://127.0.0.1:{port}/blob.bin", 4, seconds)["bytes_per_s"])
        return {"colorlabd_bytes_per_s": ours, "nginx_bytes_per_s": theirs,
                "ratio_of_means": sum(ours) / sum(theirs)}
    finally:
        nginx.send_signal(signal.SIGQUIT)
        nginx.wait()


def put_blob(state, run_id, size):
    """Adds a blob of `size` random bytes through the store's own code (bench_service_put_blob)."""
    path = os.path.join(state, "payload.bin")
    with open(path, "wb") as f:
        f.write(os.urandom(size))
    out = subprocess.run([os.path.join(ARGS.build, "bin", "bench_service_put_blob"), os.path.join(state, "s"), run_id,
                          path], capture_output=True, text=True, check=True).stdout
    added = json.loads(out)
    return added["sha256"], added["path"]


def idle_connections(url, pid, count):
    host, port = url.removeprefix("http://").split(":")
    before = rss_kib(pid)
    sockets = []
    for _ in range(count):
        s = socket.create_connection((host, int(port)))
        sockets.append(s)
    time.sleep(1.0)
    with_them = rss_kib(pid)
    still_serving = requests.get(url + "/v1", timeout=5).status_code
    for s in sockets:
        s.close()
    return {"connections": count, "rss_before_kib": before, "rss_with_kib": with_them,
            "kib_per_connection": (with_them - before) / count, "still_serving_status": still_serving}


SMALL_RUN = []


def main():
    global ARGS
    p = argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--seconds", type=int, default=10)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--time-scale", type=float, default=1000)
    p.add_argument("--parts", default="small_gets,blob,idle", help="which of small_gets, blob, idle to run")
    ARGS = p.parse_args()
    parts = set(ARGS.parts.split(","))
    with tempfile.TemporaryDirectory() as tmp:
        proc, url = start_daemon(ARGS.build, os.path.join(tmp, "state"), ARGS.time_scale)
        try:
            result = {"cores": os.cpu_count(), "seconds_per_measurement": ARGS.seconds}
            result["small_gets"] = small_gets(url, ARGS.seconds, ARGS.rounds)
            if "blob" in parts:
                result["blob_50mb"] = blob_throughput(url, os.path.join(tmp, "state"), SMALL_RUN[0], ARGS.seconds,
                                                      ARGS.rounds, tmp)
            if "idle" in parts:
                result["idle_500"] = idle_connections(url, proc.pid, 500)
            print(json.dumps(result, indent=2))
        finally:
            proc.terminate()
            proc.wait()


if __name__ == "__main__":
    main()
