#!/usr/bin/env python3
"""Shipping a backlog vs raw COPY of the same rows, side by side in one run (issue 22, "Speed"):

A bench's backlog of RUNS ended runs x MEASUREMENTS measurements (bench_fleet_backlog, colorlabd's own Store)
goes to a throwaway PostgreSQL 15 with fsync on (its defaults: fsync, synchronous_commit, full_page_writes), in
rounds of A then B:
  A  `colorlab-ship once` into a fresh database made by `colorlab-ship central-init`, with [ship]'s default
     transaction limits (transaction_runs = 100, transaction_measurements = 200,000: five transactions for the
     default backlog; each: COPY, insert-or-ignore of what central already holds, every run's digest compared,
     the position moved, one COMMIT). Its JSON report's "seconds" say where the agent's time went;
  B  psql `\\copy measurements FROM file` of the same rows (dumped from A's database beforehand) into a fresh
     database with the same central schema: the same table definition with its primary key and indexes, one COPY.
Both are timed from the client's start to its exit; rows/s counts measurements. No blobs are in the backlog.

Usage: nice -n 10 python3 bench/fleet/ship_speed.py --build build [--runs 500] [--measurements 2000] [--rounds 2]
Run as root (initdb runs as the `postgres` user). Prints one JSON document; docs/PERFORMANCE.md records it.
"""
import argparse
import json
import os
import shutil
import subprocess
import tempfile
import time

from central_load import PG_BIN, as_postgres, psql, start_postgres


def timed(cmd, **kw):
    t = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise SystemExit(f"{cmd[0]} failed ({r.returncode}): {r.stderr[-2000:]}")
    return time.monotonic() - t, r.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--runs", type=int, default=500)
    ap.add_argument("--measurements", type=int, default=2000, help="measurements per run")
    ap.add_argument("--rounds", type=int, default=2)
    a = ap.parse_args()
    build = os.path.abspath(a.build)
    root = tempfile.mkdtemp(prefix="colorlab-ship-speed-")
    os.chmod(root, 0o755)
    data = None
    try:
        state = os.path.join(root, "bench")
        t_make, _ = timed([os.path.join(build, "bin", "bench_fleet_backlog"), state, str(a.runs), str(a.measurements)])
        data, port = start_postgres(root)
        conninfo = f"host=127.0.0.1 port={port} user=postgres"
        for name in ("ak", "sk"):
            with open(os.path.join(root, name), "w") as f:  # beside the configs, which name them
                f.write("unused\n")

        def config(db):
            path = os.path.join(root, f"{db}.toml")
            with open(path, "w") as f:
                f.write(f"state_dir = \"{state}\"\n[ship]\nbench_id = \"bench-1\"\nbatch_runs = 100000\n"
                        f"postgres = \"{conninfo} dbname={db}\"\ns3_endpoint = \"http://127.0.0.1:9\"\n"
                        f"bucket = \"none\"\naccess_key_file = \"ak\"\nsecret_key_file = \"sk\"\n")
            return path

        def fresh(db):
            psql(port, "postgres", f"CREATE DATABASE {db}")
            subprocess.run([os.path.join(build, "bin", "colorlab-ship"), "--config", config(db), "central-init"],
                           check=True, stdout=subprocess.DEVNULL)

        rows_file = os.path.join(root, "measurements.copy")
        runs_file = os.path.join(root, "runs.copy")
        rounds = []
        for i in range(a.rounds):
            load_before = os.getloadavg()
            fresh(f"ship{i}")
            t_ship, out = timed([os.path.join(build, "bin", "colorlab-ship"), "--config", config(f"ship{i}"), "once"])
            shipped = int(psql(port, f"ship{i}", "SELECT count(*) FROM measurements"))
            if i == 0:  # B's input: the rows A shipped, as COPY text
                psql(port, "ship0", f"COPY benches TO '{runs_file}.benches'; COPY runs TO '{runs_file}'; "
                                    f"COPY measurements TO '{rows_file}'")
            fresh(f"raw{i}")
            psql(port, f"raw{i}", f"COPY benches FROM '{runs_file}.benches'; COPY runs FROM '{runs_file}'")
            t_copy, _ = timed(["psql", "-h", "127.0.0.1", "-p", str(port), "-U", "postgres", "-d", f"raw{i}",
                               "-v", "ON_ERROR_STOP=1", "-qc", f"\\copy measurements FROM '{rows_file}'"])
            copied = int(psql(port, f"raw{i}", "SELECT count(*) FROM measurements"))
            rounds.append({"ship_s": round(t_ship, 2), "ship_rows_per_s": round(shipped / t_ship),
                           "copy_s": round(t_copy, 2), "copy_rows_per_s": round(copied / t_copy),
                           "ratio": round((shipped / t_ship) / (copied / t_copy), 3),
                           "rows": [shipped, copied], "ship_report": {k: v for k, v in json.loads(out).items() if k not in ("divergences", "superseded")},
                           "loadavg_before": load_before, "loadavg_after": os.getloadavg()})
            psql(port, "postgres", f"DROP DATABASE ship{i}")
            psql(port, "postgres", f"DROP DATABASE raw{i}")
        fsync = psql(port, "postgres", "SHOW fsync").strip()
        print(json.dumps({"runs": a.runs, "measurements_per_run": a.measurements, "fsync": fsync,
                          "backlog_written_s": round(t_make, 1), "rounds": rounds}, indent=1))
    finally:
        if data:
            subprocess.run(as_postgres([f"{PG_BIN}/pg_ctl", "-D", data, "-m", "immediate", "stop"]),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
