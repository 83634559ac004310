"""One row of the soak's CSV every ``interval`` seconds: the daemon process (/proc: RSS, open descriptors,
threads), its state on disk (SQLite file, WAL, blob store), the data kept (measurement rows), the console page
(JS heap after a GC, DOM nodes, listeners) and the API poller's answer times since the previous row.

A row is taken under the lab's lock, so it never reads a process being killed or one not yet serving."""
from __future__ import annotations

import csv
import os
import sqlite3
import threading
import time
from datetime import datetime, timezone
from pathlib import Path

from probes import ROUTES, p99

# One p99 column per polled route: which route a slow sample came from.
ROUTE_COLUMNS = tuple("api_p99_ms_" + (r.removeprefix("/v1/") if r != "/v1" else "root") for r in ROUTES)

COLUMNS = ("sample", "wall_s", "utc", "night", "daemon_pid", "daemon_starts", "rss_kb", "fds", "threads",
           "db_bytes", "wal_bytes", "blob_bytes", "blob_files", "measurements", "runs",
           "js_heap_used", "js_heap_total", "dom_nodes", "js_listeners", "page_conn",
           "api_requests", "api_p99_ms", "api_max_ms", "api_failed", *ROUTE_COLUMNS,
           "events_a", "events_b", "load1")


def proc_stats(pid: int) -> dict:
    status = Path(f"/proc/{pid}/status").read_text()
    fields = dict(line.split(":", 1) for line in status.splitlines() if ":" in line)
    return {"rss_kb": int(fields["VmRSS"].split()[0]), "threads": int(fields["Threads"].strip()),
            "fds": len(os.listdir(f"/proc/{pid}/fd"))}


def tree_size(root: Path) -> tuple[int, int]:
    total = files = 0
    for dirpath, _dirs, names in os.walk(root):
        for n in names:
            try:
                total += os.stat(os.path.join(dirpath, n)).st_size
                files += 1
            except FileNotFoundError:  # removed by retention meanwhile
                pass
    return total, files


def file_size(path: Path) -> int:
    try:
        return path.stat().st_size
    except FileNotFoundError:
        return 0


def kept_rows(db: Path) -> tuple[int, int]:
    """Measurement rows and runs, read-only beside the running daemon (a WAL reader never blocks its writer)."""
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=10)
    try:
        return (con.execute("SELECT count(*) FROM measurements").fetchone()[0],
                con.execute("SELECT count(*) FROM runs").fetchone()[0])
    finally:
        con.close()


class Sampler(threading.Thread):
    def __init__(self, lab, page, poller, followers, csv_path: Path, interval: float):
        super().__init__(name="soak-sampler", daemon=True)
        self.lab, self.page, self.poller, self.followers = lab, page, poller, followers
        self.interval = interval
        self.csv_path = csv_path
        self.night = 0
        self.rows: list[dict] = []
        self.errors: list[str] = []
        self.stop_flag = threading.Event()
        self.t0 = time.monotonic()
        self._file = open(csv_path, "w", newline="")
        self._csv = csv.DictWriter(self._file, fieldnames=COLUMNS)
        self._csv.writeheader()
        self._file.flush()

    def sample(self) -> dict:
        times, failed, by_route = self.poller.take()
        with self.lab.lock:
            pid, starts = self.lab.pid, self.lab.starts
            row = {"daemon_pid": pid, "daemon_starts": starts, **proc_stats(pid)}
        state = self.lab.state
        row["db_bytes"] = file_size(state / "colorlab.db")
        row["wal_bytes"] = file_size(state / "colorlab.db-wal")
        row["blob_bytes"], row["blob_files"] = tree_size(state / "blobs")
        row["measurements"], row["runs"] = kept_rows(state / "colorlab.db")
        row.update(self.page.metrics())
        row["page_conn"] = self.page.connection()
        row.update(api_requests=len(times), api_failed=failed,
                   api_p99_ms=None if not times else round(p99(times), 2),
                   api_max_ms=None if not times else round(max(times), 2))
        for route, column in zip(ROUTES, ROUTE_COLUMNS):
            row[column] = None if not by_route[route] else round(p99(by_route[route]), 2)
        row["events_a"], row["events_b"] = (f.count for f in self.followers)
        row["load1"] = os.getloadavg()[0]
        row.update(sample=len(self.rows) + 1, wall_s=round(time.monotonic() - self.t0, 1), night=self.night,
                   utc=datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"))
        self.rows.append(row)
        self._csv.writerow(row)
        self._file.flush()
        return row

    def run(self) -> None:
        due = time.monotonic()
        while not self.stop_flag.is_set():
            try:
                self.sample()
            except Exception as e:  # noqa: BLE001  (a missed sample is a finding, reported at the end)
                self.errors.append(f"sample at {time.monotonic() - self.t0:.1f} s: {type(e).__name__}: {e}")
            due += self.interval
            self.stop_flag.wait(max(0.0, due - time.monotonic()))

    def stop(self) -> None:
        """Stops the loop, then takes one last row: the state after the night(s)."""
        self.stop_flag.set()
        self.join(120)
        try:
            self.sample()
        except Exception as e:  # noqa: BLE001
            self.errors.append(f"final sample: {type(e).__name__}: {e}")
        self._file.close()
