"""The measurements a night kept, per run, read from the daemon's SQLite file: how many rows, whether their seqs run
1..N without a gap or a repeat, whether a step key was recorded twice, and two digests:

- ``shape``: sha256 over each row's (seq, step, instrument, quantity, unit) — what was measured, in which order.
  A killed night must have the same shape as an unkilled night of the same parameters: that is the "no lost, no
  doubled measurement" check the soak can make honestly.
- ``values``: sha256 over the whole rows (values and data too). The simulated lab's noise comes from one random
  stream per simulator process, which a kill -9 restarts (and which runs on from night to night), so values are
  not expected to match between nights; the digest is recorded so a re-run of the same seed can be compared."""
from __future__ import annotations

import hashlib
import json
import sqlite3
from pathlib import Path


def run_ledger(db: Path, run_id: str) -> dict:
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=10)
    try:
        rows = con.execute("SELECT seq, step, instrument_id, quantity, unit, value, data FROM measurements "
                           "WHERE run_id = ? ORDER BY seq", (run_id,)).fetchall()
    finally:
        con.close()
    shape, values = hashlib.sha256(), hashlib.sha256()
    seen: set[str] = set()
    repeated: list[str] = []
    for seq, step, instrument, quantity, unit, value, data in rows:
        shape.update(json.dumps([seq, step, instrument, quantity, unit]).encode())
        values.update(json.dumps([seq, step, instrument, quantity, unit, value, data]).encode())
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
