#!/usr/bin/env python3
"""colorlab-central beside a bench on the same routes, in one run (issue 22, "Speed"):

A throwaway PostgreSQL 15 (fsync on) gets the central schema from `colorlab-ship central-init`, then a catalog of
BENCHES benches x RUNS runs x MEASUREMENTS measurements (10.2 M by default) written by SQL; bench-1's share is
written, row for row the same, into a colorlabd state directory (the daemon's own schema, created by starting it
once). Then wrk -t2 -c32 --latency, alternating bench and central (and --baseline, another colorlab-central binary on
the same catalog), on
  - the run listing, 50 runs a page (GET /v1/runs?limit=50),
  - one run's measurement page, 500 a page (GET /v1/runs/{id}/measurements?limit=500, a run in the middle): asked
    again and again, central answers it from memory (fleet/include/colorlab/fleet/central_cache.hpp), and
  - the first page of a different run each request (bench-1's 2,000 runs in turn), which central builds afresh.
Each figure comes with the CPU milliseconds per request of the server process (and of all of PostgreSQL for
central), read from /proc before and after: on a shared machine GETs/s follow the load, CPU per request hardly.
Blobs are not part of this bench (the bucket is not started).

Usage: python3 bench/fleet/central_load.py --build build [--runs 2000] [--measurements 1700] [--benches 3]
       [--seconds 10] [--rounds 2] [--threads 4] [--baseline path/to/colorlab-central]
Run as root (PostgreSQL's initdb runs as the `postgres` user) with wrk installed. Prints one JSON document;
docs/PERFORMANCE.md records the figures and this command.
"""
import argparse
import json
import os
import pwd
import re
import shutil
import signal
import socket
import sqlite3
import subprocess
import tempfile
import time

PG_BIN = "/usr/lib/postgresql/15/bin"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def as_postgres(cmd):
    return ["runuser", "-u", "postgres", "--"] + cmd if os.geteuid() == 0 else cmd


def start_postgres(root):
    data = os.path.join(root, "pg")
    os.makedirs(data)
    if os.geteuid() == 0:
        shutil.chown(root, "postgres")
        shutil.chown(data, "postgres")
    subprocess.run(as_postgres([f"{PG_BIN}/initdb", "-D", data, "-A", "trust", "-U", "postgres"]), check=True,
                   stdout=subprocess.DEVNULL)
    port = free_port()
    subprocess.run(as_postgres([f"{PG_BIN}/pg_ctl", "-D", data, "-w", "-l", os.path.join(data, "log"), "-o",
                                f"-p {port} -k {data} -c listen_addresses=127.0.0.1 -c max_wal_size=4GB", "start"]),
                   check=True, stdout=subprocess.DEVNULL)
    return data, port


def psql(port, db, sql):
    return subprocess.run(["psql", "-h", "127.0.0.1", "-p", str(port), "-U", "postgres", "-d", db, "-v",
                           "ON_ERROR_STOP=1", "-qAt", "-c", sql], check=True, capture_output=True, text=True).stdout


def run_id(bench, i):
    # UUIDv7-shaped and ordered by (i, bench): the runs of all benches interleave in the listing, as they would.
    return f"{0x0190000000 + i:010x}"[:8] + "-" + f"{0x0190000000 + i:010x}"[8:] + f"{bench:02x}-7000-8000-{i:012x}"


def write_central(port, benches, runs, per_run):
    for b in range(1, benches + 1):
        psql(port, "central", f"INSERT INTO benches (id, name, software_version, bench_schema) VALUES "
                              f"('bench-{b}', 'Bench {b}', 'bench', 1)")
    # The same rows as write_bench() writes for bench-1; ids as run_id() builds them.
    ident = ("substr(lpad(to_hex(6710886400 + i), 10, '0'), 1, 8) || '-' || "
             "substr(lpad(to_hex(6710886400 + i), 10, '0'), 9, 2) || lpad(to_hex(b), 2, '0') || "
             "'-7000-8000-' || lpad(to_hex(i), 12, '0')")
    psql(port, "central", f"""
      INSERT INTO runs (id, bench_id, bench_seq, campaign, params, status, simulated, instruments, created_at,
                        started_at, finished_at, summary, error, script_sha256, ended_event)
      SELECT {ident}, 'bench-' || b, i, 'chart-read', '{{"chart":"sg"}}', 'finished_ok', 1, '[]',
             '2026-11-28T20:00:00.000Z', '2026-11-28T20:00:00.000Z', '2026-11-28T20:10:00.000Z', '{{}}', NULL, NULL, i
      FROM generate_series(1, {benches}) b, generate_series(1, {runs}) i""")
    # Loaded without its primary key and index, which are built once afterwards (sorted, not row by row: the
    # "Populating a Database" advice of PostgreSQL's manual), so 10 M rows take minutes rather than an hour; the
    # table and its indexes end up as central-init defines them, which the check below confirms.
    psql(port, "central", "ALTER TABLE measurements DROP CONSTRAINT measurements_pkey; "
                          "DROP INDEX measurements_by_seq")
    psql(port, "central", f"""
      SET synchronous_commit = off;
      INSERT INTO measurements (run_id, step, seq, instrument_id, simulated, quantity, value, unit, data, measured_at)
      SELECT r.id, 'patch/' || lpad(j::text, 5, '0'), (r.bench_seq - 1) * {per_run} + j, 'meter', 1, 'Y',
             (((r.bench_seq - 1) * {per_run} + j) % 1000)::float8 / 7.0, 'cd/m2', '{{"xyz":[1.5,2.5,3.5]}}',
             '2026-11-28T20:05:00.000Z'
      FROM runs r, generate_series(1, {per_run}) j""")
    psql(port, "central", "SET maintenance_work_mem = '1GB'; "
                          "ALTER TABLE measurements ADD PRIMARY KEY (run_id, step); "
                          "CREATE INDEX measurements_by_seq ON measurements (run_id, seq)")
    psql(port, "central", "VACUUM ANALYZE")


def write_bench(db_path, runs, per_run):
    db = sqlite3.connect(db_path)
    db.execute("PRAGMA synchronous = OFF")
    with db:
        db.executemany(
            "INSERT INTO runs (seq, id, campaign, params, status, simulated, instruments, created_at, started_at, "
            "finished_at, summary, error) VALUES (?, ?, 'chart-read', '{\"chart\":\"sg\"}', 'finished_ok', 1, '[]', "
            "'2026-11-28T20:00:00.000Z', '2026-11-28T20:00:00.000Z', '2026-11-28T20:10:00.000Z', '{}', NULL)",
            ((i, run_id(1, i)) for i in range(1, runs + 1)))
        db.executemany(
            "INSERT INTO measurements (run_id, seq, step, instrument_id, simulated, quantity, value, unit, data, "
            "measured_at) VALUES (?, ?, ?, 'meter', 1, 'Y', ?, 'cd/m2', '{\"xyz\":[1.5,2.5,3.5]}', "
            "'2026-11-28T20:05:00.000Z')",
            ((run_id(1, i), (i - 1) * per_run + j, f"patch/{j:05d}", (((i - 1) * per_run + j) % 1000) / 7.0)
             for i in range(1, runs + 1) for j in range(1, per_run + 1)))
    db.close()


def start_daemon(build, root):
    state = os.path.join(root, "bench")
    os.makedirs(state, exist_ok=True)
    with open(os.path.join(root, "lab.toml"), "w") as f:
        f.write("[genicam]\nenabled = false\n")
    with open(os.path.join(root, "colorlabd.toml"), "w") as f:
        f.write(f"[simulator]\nenabled = true\ntime_scale = 1000\nconfig = \"{os.path.join(root, 'lab.toml')}\"\n")
    endpoint = os.path.join(state, "colorlabd.endpoint")
    if os.path.exists(endpoint):
        os.remove(endpoint)
    proc = subprocess.Popen([os.path.join(build, "bin", "colorlabd"), "--config", os.path.join(root, "colorlabd.toml"),
                             "--state", state, "--listen", "127.0.0.1:0"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for _ in range(1200):
        if os.path.exists(endpoint):
            with open(endpoint) as f:
                return proc, json.load(f)["url"]
        time.sleep(0.05)
    proc.kill()
    raise SystemExit("colorlabd did not start")


def start_central(build, root, port, threads, binary=None, name="central"):
    c = os.path.join(root, name)
    os.makedirs(c)
    for name in ("ak", "sk"):
        with open(os.path.join(c, name), "w") as f:
            f.write("unused\n")
    with open(os.path.join(c, "central.toml"), "w") as f:
        f.write(f"state_dir = \"{c}/state\"\n[central]\nport = 0\nthreads = {threads}\n"
                f"postgres = \"host=127.0.0.1 port={port} dbname=central user=postgres\"\n"
                f"s3_endpoint = \"http://127.0.0.1:9\"\nbucket = \"none\"\naccess_key_file = \"ak\"\nsecret_key_file = \"sk\"\n")
    proc = subprocess.Popen([binary or os.path.join(build, "bin", "colorlab-central"), "--config", os.path.join(c, "central.toml"),
                             "serve"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    return proc, json.loads(proc.stdout.readline())["url"]


def cpu_seconds(pid, children=False):
    """User + system CPU of a process (with its reaped children's when asked), from /proc/<pid>/stat."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    ticks = int(fields[11]) + int(fields[12]) + (int(fields[13]) + int(fields[14]) if children else 0)
    return ticks / os.sysconf("SC_CLK_TCK")


def postgres_cpu_seconds(data):
    """The whole PostgreSQL server's CPU: the postmaster with the backends it reaped, plus its live children."""
    with open(os.path.join(data, "postmaster.pid")) as f:
        postmaster = int(f.readline())
    total = cpu_seconds(postmaster, children=True)
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            if int(fields[1]) == postmaster:
                total += cpu_seconds(int(entry))
        except (OSError, ValueError, IndexError):
            pass  # a backend that ended meanwhile is in the postmaster's reaped children
    return total


# Each request a different run's first page, each wrk thread starting half the list away from the other: the runs
# cycle through more pages than central's answer cache holds (64 MiB, ~870 pages of ~75 KB), so every request is
# built from PostgreSQL: the figure for pages nobody asked for lately.
DISTINCT_RUNS_LUA = """
local n = 0
function setup(thread)
  thread:set("offset", n * math.floor(#ids / 2))
  n = n + 1
end
function init(args)
  i = offset or 0
end
function request()
  i = i + 1
  return wrk.format("GET", "/v1/runs/" .. ids[(i % #ids) + 1] .. "/measurements?limit=500")
end
"""


def wrk(url, seconds, connections=32, threads=2, script=None, cpu=None):
    """wrk's figures, plus the CPU milliseconds per request of each process in `cpu` ({name: () -> seconds})."""
    before = {name: f() for name, f in (cpu or {}).items()}
    cmd = ["wrk", f"-t{threads}", f"-c{connections}", f"-d{seconds}s", "--latency"] + (["-s", script] if script else [])
    out = subprocess.run(cmd + [url], capture_output=True, text=True, check=True).stdout
    rps = float(re.search(r"Requests/sec:\s+([\d.]+)", out).group(1))
    total = int(re.search(r"(\d+) requests in", out).group(1))
    p99 = re.search(r"99%\s+([\d.]+)(us|ms|s)", out)
    errors = re.search(r"Non-2xx or 3xx responses:\s+(\d+)", out)
    r = {"requests_per_s": rps, "p99_ms": round(float(p99.group(1)) * {"us": 1e-3, "ms": 1.0, "s": 1e3}[p99.group(2)], 2),
         "non_2xx": int(errors.group(1)) if errors else 0}
    for name, f in (cpu or {}).items():
        # CPU time per request hardly depends on how many other processes share the cores, unlike GETs/s.
        r[f"cpu_ms_per_request_{name}"] = round((f() - before[name]) * 1e3 / max(total, 1), 3)
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--benches", type=int, default=3)
    ap.add_argument("--runs", type=int, default=2000, help="runs per bench")
    ap.add_argument("--measurements", type=int, default=1700, help="measurements per run")
    ap.add_argument("--seconds", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--threads", type=int, default=4, help="colorlab-central's HTTP threads")
    ap.add_argument("--baseline", help="another colorlab-central binary (e.g. the previous commit's) measured beside "
                                       "this one on the same catalog, in the same run")
    a = ap.parse_args()
    build = os.path.abspath(a.build)
    root = tempfile.mkdtemp(prefix="colorlab-central-bench-")
    os.chmod(root, 0o755)
    procs, data = [], None
    try:
        t0 = time.time()
        data, port = start_postgres(root)
        psql(port, "postgres", "CREATE DATABASE central")
        with open(os.path.join(root, "ship.toml"), "w") as f:
            f.write(f"state_dir = \"{root}/bench\"\n[ship]\nbench_id = \"bench-1\"\n"
                    f"postgres = \"host=127.0.0.1 port={port} dbname=central user=postgres\"\n"
                    f"s3_endpoint = \"http://127.0.0.1:9\"\nbucket = \"none\"\naccess_key_file = \"central/ak\"\n"
                    f"secret_key_file = \"central/sk\"\n")
        subprocess.run([os.path.join(build, "bin", "colorlab-ship"), "--config", os.path.join(root, "ship.toml"),
                        "central-init"], check=True, stdout=subprocess.DEVNULL)
        write_central(port, a.benches, a.runs, a.measurements)
        t1 = time.time()
        daemon, bench_url = start_daemon(build, root)  # creates the bench's schema
        daemon.send_signal(signal.SIGTERM)
        daemon.wait(60)
        write_bench(os.path.join(root, "bench", "colorlab.db"), a.runs, a.measurements)
        t2 = time.time()
        daemon, bench_url = start_daemon(build, root)
        procs.append(daemon)
        central, central_url = start_central(build, root, port, a.threads)
        procs.append(central)
        sides = [("bench", bench_url), ("central", central_url)]
        cpu = {"bench": {"server": lambda: cpu_seconds(daemon.pid)},
               "central": {"server": lambda: cpu_seconds(central.pid), "postgres": lambda: postgres_cpu_seconds(data)}}
        if a.baseline:
            baseline, baseline_url = start_central(build, root, port, a.threads, os.path.abspath(a.baseline), "baseline")
            procs.append(baseline)
            sides.append(("central baseline", baseline_url))
            cpu["central baseline"] = {"server": lambda: cpu_seconds(baseline.pid),
                                       "postgres": lambda: postgres_cpu_seconds(data)}
        rows = int(psql(port, "central", "SELECT count(*) FROM measurements"))
        # Bytes per row for docs/fleet.md "Sizing": heap (with TOAST), each index, and the total.
        sizes = {}
        for table in ("measurements", "runs"):
            heap, indexes, total, n = psql(port, "central", f"""
              SELECT pg_table_size('{table}'), pg_indexes_size('{table}'), pg_total_relation_size('{table}'),
                     (SELECT count(*) FROM {table})""").strip().split("|")
            per_index = dict(line.split("|") for line in psql(port, "central", f"""
              SELECT indexrelid::regclass, pg_relation_size(indexrelid) FROM pg_index
              WHERE indrelid = '{table}'::regclass""").strip().splitlines())
            sizes[table] = {"rows": int(n), "table_bytes": int(heap), "index_bytes": int(indexes),
                            "total_bytes": int(total), "bytes_per_row": round(int(total) / int(n), 1),
                            "indexes": {k: int(v) for k, v in per_index.items()}}
        plans = {}
        for name, sql in (("measurement page", f"SELECT seq, step, instrument_id, simulated, quantity, value, unit, "
                                               f"data, measured_at FROM measurements WHERE run_id = "
                                               f"'{run_id(1, a.runs // 2)}' AND seq > 0 ORDER BY seq LIMIT 501"),
                          ("run listing", "SELECT r.id FROM runs r JOIN benches b ON b.id = r.bench_id "
                                          "ORDER BY r.id DESC LIMIT 51")):
            plans[name] = psql(port, "central", "EXPLAIN (ANALYZE, BUFFERS, TIMING OFF) " + sql).strip().splitlines()
        middle = run_id(1, a.runs // 2)
        script = os.path.join(root, "distinct_runs.lua")
        with open(script, "w") as f:
            # bench-1's runs: the bench holds these too, so both sides build the same pages.
            f.write("ids = {" + ",".join(f'"{run_id(1, i)}"' for i in range(1, a.runs + 1)) + "}\n" + DISTINCT_RUNS_LUA)
        routes = {"run listing, 50 a page": ("/v1/runs?limit=50", None),
                  "measurement page, 500 a page": (f"/v1/runs/{middle}/measurements?limit=500", None),
                  "measurement pages, a different run each request": ("/", script)}
        results = {name: {side: [] for side, _ in sides} for name in routes}
        load_before = os.getloadavg()
        for _ in range(a.rounds):
            for name, (path, lua) in routes.items():
                for side, url in sides:
                    r = wrk(url + path, a.seconds, script=lua, cpu=cpu[side])
                    r["loadavg_1min"] = round(os.getloadavg()[0], 1)  # the machine is shared: say its load
                    results[name][side].append(r)
        print(json.dumps({"central_measurements": rows, "benches": a.benches, "runs_per_bench": a.runs,
                          "bench_measurements": a.runs * a.measurements, "central_threads": a.threads,
                          "load_seconds": {"central_sql": round(t1 - t0, 1), "bench_sqlite": round(t2 - t1, 1)},
                          "loadavg_before": load_before, "loadavg_after": os.getloadavg(), "sizes": sizes,
                          "plans": plans, "results": results}, indent=1))
    finally:
        for p in procs:
            p.kill()
            p.wait()
        if data:
            subprocess.run(as_postgres([f"{PG_BIN}/pg_ctl", "-D", data, "-m", "immediate", "stop"]),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
