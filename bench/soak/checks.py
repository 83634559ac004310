"""What the soak concludes from its nights and samples.

``compare_nights``: every night's runs against night 1's (never killed): same steps, each run's rows and shape
digest equal, seqs 1..N, no step key twice; and what each kill left committed (every run's rows then, values
and data included) still there unchanged at the night's end (ledger.check_kept). ``growth``: per series, the
per-night medians, the slope per simulated night and per wall hour after night 1, and the spread after night 1
against night 1's own level."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

SERIES = ("rss_kb", "fds", "threads", "db_bytes", "wal_bytes", "blob_bytes", "measurements", "js_heap_used",
          "dom_nodes", "js_listeners", "api_p99_ms")


def compare_nights(nights: list[dict]) -> dict:
    problems: list[str] = []
    per_night = []
    if not nights:
        return {"problems": ["no night ran"], "nights": []}
    ref = nights[0]["ledger"]
    for night in nights:
        n = night["night"]
        if night["state"] != "done":
            problems.append(f"night {n} ended {night['state']}: {night['items']}")
        # Each kill's figure counts every run the file held then, earlier nights' too: rows re-read, not rows new.
        row = {"night": n, "kills": len(night["kills"]), "rows": 0, "runs_equal_to_night_1": 0, "runs": 0,
               "rows_reread_after_kills": 0}
        for k, kill in enumerate(night["kills"], 1):
            if "kept_error" in kill or "kept" in kill:
                problems.append(f"night {n} kill {k}: what it left committed was not checked "
                                f"({kill.get('kept_error') or 'the night did not check it'})")
            elif "kept_check" in kill:  # absent from a soak written before the check (nothing to report then)
                row["rows_reread_after_kills"] += kill["kept_check"]["rows"]
                problems += [f"night {n} kill {k}: {c}" for c in kill["kept_check"]["changed"]]
        if set(night["ledger"]) != set(ref):
            problems.append(f"night {n} has steps {sorted(night['ledger'])}, night 1 {sorted(ref)}")
        for step, led in night["ledger"].items():
            row["runs"] += 1
            row["rows"] += led["rows"]
            if led["rows"] and not led["seq_contiguous"]:
                problems.append(f"night {n} {step}: seqs are not 1..{led['rows']}")
            if led.get("repeated_steps"):
                problems.append(f"night {n} {step}: step keys recorded twice: {led['repeated_steps'][:5]}")
            r = ref.get(step)
            if r and (led["rows"], led.get("shape")) == (r["rows"], r.get("shape")):
                row["runs_equal_to_night_1"] += 1
            elif r:
                problems.append(f"night {n} {step}: {led['rows']} rows, shape {led.get('shape')}; night 1: "
                                f"{r['rows']} rows, shape {r.get('shape')}")
        per_night.append(row)
    return {"problems": problems, "nights": per_night}


def _slope(x, y) -> float | None:
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = ~np.isnan(y)
    if ok.sum() < 2 or np.ptp(x[ok]) == 0:
        return None
    return float(np.polyfit(x[ok], y[ok], 1)[0])


def growth(csv_path: Path, *, time_scale: float) -> dict:
    """Per series and night: median, high-water mark (max) and the last sample. ``flat_spread_pct``: the spread of
    the later nights' high-water marks against their mean — the "flat within 10 % after the first night" figure.
    ``per_night`` is the slope of those marks per simulated night, ``per_wall_hour`` the slope of every sample after
    night 1 against wall time. For the store: bytes per measurement row kept at each night's end."""
    df = pd.read_csv(csv_path)
    out: dict = {"time_scale": time_scale, "samples": int(len(df)), "wall_hours": float(df["wall_s"].max() / 3600),
                 "series": {}}
    nights = sorted(int(n) for n in df["night"].unique() if n >= 1)
    after = df["night"] >= 2
    for s in SERIES:
        if s not in df:
            continue
        col = pd.to_numeric(df[s], errors="coerce")
        by = {n: col[df["night"] == n] for n in nights}
        entry = {"median_by_night": {n: float(v.median()) for n, v in by.items()},
                 "max_by_night": {n: float(v.max()) for n, v in by.items()},
                 "end_by_night": {n: float(v.iloc[-1]) for n, v in by.items()}}
        later = [v for n, v in entry["max_by_night"].items() if n >= 2]
        entry["per_night"] = _slope([n for n in nights if n >= 2], later) if len(later) >= 2 else None
        slope = _slope(df["wall_s"][after], col[after])
        entry["per_wall_hour"] = None if slope is None else slope * 3600
        if later and np.mean(later):
            entry["flat_spread_pct"] = float(100.0 * (max(later) - min(later)) / np.mean(later))
        out["series"][s] = entry
    rows = {n: float(pd.to_numeric(df["measurements"], errors="coerce")[df["night"] == n].iloc[-1]) for n in nights}
    for s in ("db_bytes", "blob_bytes"):
        ends = out["series"][s]["end_by_night"]
        out["series"][s]["bytes_per_row_by_night"] = {n: ends[n] / rows[n] for n in nights if rows[n]}
    return out
