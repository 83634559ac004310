"""The measurements a night kept, per run, read from the daemon's SQLite file: how many rows, whether their seqs run
1..N without a gap or a repeat, whether a step key was recorded twice, and two digests:

- ``shape``: sha256 over each row's (seq, step, instrument, quantity, unit) — what was measured, in which order.
  A killed night must have the same shape as an unkilled night of the same parameters: that is the "no lost, no
  doubled measurement" check the soak can make honestly.
- ``values``: sha256 over the whole rows (values and data too). The simulated lab's noise comes from one random
  stream per simulator process, which a kill -9 restarts (and which runs on from night to night), so values are
  not expected to match between nights; the digest is recorded so a re-run of the same seed can be compared.

What values can be compared across a kill is what was committed before it: ``committed_values`` reads every run's
rows from the file the killed daemon left (before it is started again), and ``check_kept`` finds, once the night has
ended, each of those runs' first rows unchanged — the same seqs with every column the same (KEPT_COLUMNS: values,
data and the time measured included).
A resume that lost, rewrote or re-recorded a committed measurement fails there. The store only ever inserts
measurements (primary key (run_id, step), seq the run's next), so this guards against a regression, not a path the
daemon has today."""
from __future__ import annotations

import hashlib
import json
import sqlite3
from pathlib import Path


ROW_COLUMNS = "seq, step, instrument_id, quantity, unit, value, data"
# What a kill's re-read compares: every column of a row but its run (daemon/store/src/schema.cpp's measurements), the
# time it was measured and whether it was simulated among them. Since 2026-11-30 23:10; the two weeks of that evening
# compared ROW_COLUMNS' seven.
KEPT_COLUMNS = "seq, step, instrument_id, simulated, quantity, value, unit, data, measured_at"


def _read(db: Path, sql: str, args=()) -> list[tuple]:
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=10)
    try:
        return con.execute(sql, args).fetchall()
    finally:
        con.close()


def _row_bytes(row: tuple) -> bytes:
    return json.dumps(list(row)).encode()


def run_ledger(db: Path, run_id: str) -> dict:
    rows = _read(db, f"SELECT {ROW_COLUMNS} FROM measurements WHERE run_id = ? ORDER BY seq", (run_id,))
    shape, values = hashlib.sha256(), hashlib.sha256()
    seen: set[str] = set()
    repeated: list[str] = []
    for seq, step, instrument, quantity, unit, value, data in rows:
        shape.update(json.dumps([seq, step, instrument, quantity, unit]).encode())
        values.update(_row_bytes((seq, step, instrument, quantity, unit, value, data)))
        if step in seen:
            repeated.append(step)
        seen.add(step)
    seqs = [r[0] for r in rows]
    return {"run_id": run_id, "rows": len(rows), "seq_contiguous": seqs == list(range(1, len(rows) + 1)),
            "repeated_steps": repeated, "steps": sorted(seen), "shape": shape.hexdigest()[:16],
            "values": values.hexdigest()[:16]}


def group_ledger(db: Path, group: dict) -> dict:
    """{step: ledger} for every item of a queue group that got a run."""
    out = {}
    for item in group["items"]:
        if item.get("run_id"):
            out[item["step"]] = {**run_ledger(db, item["run_id"]), "state": item["state"]}
        else:
            out[item["step"]] = {"run_id": None, "rows": 0, "state": item["state"]}
    return out


def _run_digests(db: Path, up_to: dict[str, int] | None = None) -> dict:
    """{run_id: {"rows": n, "last_seq": s, "values": digest of KEPT_COLUMNS}} in one pass over the file; with
    ``up_to`` ({run_id: seq}), only those runs and of each only its rows up to that seq."""
    digests: dict[str, dict] = {}
    for row in _read(db, f"SELECT run_id, {KEPT_COLUMNS} FROM measurements ORDER BY run_id, seq"):
        run, seq = row[0], row[1]
        if up_to is not None and (run not in up_to or seq > up_to[run]):
            continue
        entry = digests.setdefault(run, {"rows": 0, "last_seq": 0, "hash": hashlib.sha256()})
        entry["rows"] += 1
        entry["last_seq"] = seq
        entry["hash"].update(_row_bytes(row[1:]))
    return {run: {"rows": e["rows"], "last_seq": e["last_seq"], "values": e["hash"].hexdigest()}
            for run, e in digests.items()}


def committed_values(db: Path) -> dict:
    """{run_id: {"rows": n, "last_seq": s, "values": digest}} over every run's rows in the file as it is now."""
    return _run_digests(db)


def check_kept(db: Path, kept: dict) -> dict:
    """Each run of ``kept`` (committed_values at a kill) against the file now: its rows up to the seq it had then
    must be the same rows, whole. Returns {"runs", "rows", "rows_by_run", "changed": [what differs]}."""
    now = _run_digests(db, {run: then["last_seq"] for run, then in kept.items()})
    changed = []
    for run_id, then in kept.items():
        found = now.get(run_id, {"rows": 0, "values": None})
        if (found["rows"], found["values"]) != (then["rows"], then["values"]):
            what = "other values in them" if found["rows"] == then["rows"] else f"{found['rows']} rows there"
            changed.append(f"run {run_id}: {then['rows']} rows up to seq {then['last_seq']} at the kill, now {what}")
    return {"runs": len(kept), "rows": sum(e["rows"] for e in kept.values()),
            "rows_by_run": {run: e["rows"] for run, e in kept.items()}, "changed": changed}


def check_kills(db: Path, kills: list[dict]) -> None:
    """Replaces each kill's ``kept`` (what was committed when it fell) with ``kept_check`` against the file now, or
    with ``kept_error`` when the file cannot be read: the soak goes on and its checks report the kill unchecked."""
    for kill in kills:
        if "kept" in kill:
            kept = kill.pop("kept")
            try:
                kill["kept_check"] = check_kept(db, kept)
            except Exception as e:  # noqa: BLE001 — any failure to read leaves this kill unchecked, said so
                kill["kept_error"] = f"{type(e).__name__}: {e}"
