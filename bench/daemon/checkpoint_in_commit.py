#!/usr/bin/env python3
"""What a COMMIT that crosses SQLite's auto-checkpoint threshold costs the thread that made it, and whether the
write lock is held meanwhile (issue 27).

Until 2026-11-30 colorlabd's store set `PRAGMA wal_autocheckpoint = 1000` on each writer connection, so the commit
that brought the WAL to 1000 pages checkpointed it, inside that COMMIT's call, on whichever thread made it — the step
committer's or the io thread's — and its Transaction::commit logged the whole call as the time it "held the write
lock; other writers waited as long". This bench measures both halves of that sentence with the same SQLite library
colorlabd links (Python's sqlite3 module over Debian's libsqlite3). Since then the store's own WAL hook runs the
same PASSIVE checkpoint on the committer's connection only (daemon/store wal_policy.hpp), and the io thread's hands
it over:

- per trial, a writer `a` makes one commit of --rows rows of 4 KB after the WAL has been filled to just below the
  threshold by another connection `b`; `a` runs with the threshold (as colorlabd) and without it
  (`wal_autocheckpoint = 0`), alternately, the same rows each time;
- meanwhile `b`, on its own thread, tries BEGIN IMMEDIATE every 0.2 ms without waiting and, when it gets the lock,
  rolls back at once (writing nothing, so it does not compete with the checkpoint's I/O); the bench counts how
  often it got the write lock while `a`'s COMMIT call had not yet returned.

Usage: bench/daemon/checkpoint_in_commit.py [--trials 5] [--rows 300] [--dir /var/tmp]
"""
import argparse
import os
import sqlite3
import statistics
import tempfile
import threading
import time


PAGE = 4096
THRESHOLD = 1000  # colorlabd's kWalAutocheckpointPages


def fill_below_threshold(b, path):
    """Commits of b's alone (b never checkpoints) until the WAL holds about 800 pages: a's commit then crosses
    the threshold. (A WAL frame is a page and a 24-byte header.)"""
    while os.path.getsize(path + "-wal") < (THRESHOLD - 200) * (PAGE + 24):
        b.execute("BEGIN IMMEDIATE")
        b.executemany("INSERT INTO t VALUES(?)", [(os.urandom(4000),)] * 25)
        b.execute("COMMIT")


def one_commit(a, b, path, rows, autocheckpoint):
    a.execute(f"PRAGMA wal_autocheckpoint = {THRESHOLD if autocheckpoint else 0}")
    fill_below_threshold(b, path)
    db_before = os.path.getsize(path)
    a.execute("BEGIN IMMEDIATE")
    a.executemany("INSERT INTO t VALUES(?)", [(os.urandom(4000),)] * rows)
    got, done = [], threading.Event()

    def other_writer():
        while not done.is_set():
            try:
                b.execute("BEGIN IMMEDIATE")
                got.append(time.perf_counter())
                b.execute("ROLLBACK")
            except sqlite3.OperationalError as e:
                if b.in_transaction:  # not a refusal of the lock: never count a failure as "held"
                    b.execute("ROLLBACK")
                    raise SystemExit(f"the other writer failed inside its transaction: {e}")
                # else the lock was held: SQLITE_BUSY at once (timeout 0)
            time.sleep(0.0002)

    th = threading.Thread(target=other_writer)
    t0 = time.perf_counter()
    th.start()
    a.execute("COMMIT")
    t1 = time.perf_counter()
    db_after = os.path.getsize(path)
    done.set()
    th.join()
    inside = [g for g in got if t0 < g < t1]
    # Afterwards, empty the WAL so every trial starts alike.
    busy, _, _ = b.execute("PRAGMA wal_checkpoint(TRUNCATE)").fetchone()
    if busy:
        raise SystemExit("the WAL could not be emptied between trials")
    return {"commit_ms": (t1 - t0) * 1000, "checkpointed": db_after > db_before,
            "other_writer_got_lock_inside": len(inside), "first_ms": (inside[0] - t0) * 1000 if inside else None}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=5)
    ap.add_argument("--rows", type=int, default=300)
    ap.add_argument("--dir", default="/var/tmp", help="a directory on the disk to measure (not a tmpfs)")
    args = ap.parse_args()
    print(f"SQLite {sqlite3.sqlite_version}")
    with tempfile.TemporaryDirectory(dir=args.dir) as d:
        path = os.path.join(d, "t.db")
        a, b = (sqlite3.connect(path, isolation_level=None, check_same_thread=False, timeout=0) for _ in range(2))
        for c in (a, b):
            c.execute("PRAGMA journal_mode = WAL")
            c.execute("PRAGMA synchronous = FULL")  # as colorlabd's store
        b.execute("PRAGMA wal_autocheckpoint = 0")
        a.execute("CREATE TABLE t(x BLOB)")
        results = {True: [], False: []}
        for _ in range(args.trials):
            for auto in (True, False):
                results[auto].append(one_commit(a, b, path, args.rows, auto))
        for auto, label in ((True, "wal_autocheckpoint = 1000 (colorlabd)"), (False, "wal_autocheckpoint = 0")):
            r = results[auto]
            med = statistics.median(x["commit_ms"] for x in r)
            firsts = [x["first_ms"] for x in r if x["first_ms"] is not None]
            print(f"{label:40s} COMMIT call median {med:6.1f} ms (each: "
                  + ", ".join(f"{x['commit_ms']:.1f}" for x in r) + f"); checkpointed inside it: "
                  f"{sum(x['checkpointed'] for x in r)} of {len(r)}; the other writer got the lock inside the call "
                  f"in {sum(1 for x in r if x['other_writer_got_lock_inside'])} of {len(r)}"
                  + (f", first after {statistics.median(firsts):.1f} ms (median)" if firsts else ""))
        ratio = statistics.median(x["commit_ms"] for x in results[True]) / statistics.median(
            x["commit_ms"] for x in results[False])
        print(f"the COMMIT call with the checkpoint / without: {ratio:.1f}x")


if __name__ == "__main__":
    main()
