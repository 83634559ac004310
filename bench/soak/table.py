#!/usr/bin/python3
"""The soak's summary.json as the Markdown tables docs/soak.md shows: per series, night 1's median, the medians of
the later nights, the growth per simulated night and per wall hour after night 1; per night, its wall time, kills,
rows and runs equal to night 1's. ``table.py OUT_DIR`` (the directory week.py wrote)."""
from __future__ import annotations

import json
import sys
from pathlib import Path

UNITS = {"rss_kb": ("daemon RSS", 1 / 1024, "MiB"), "fds": ("open descriptors", 1, ""),
         "threads": ("threads", 1, ""), "db_bytes": ("SQLite file", 1 / 2**20, "MiB"),
         "wal_bytes": ("SQLite WAL", 1 / 2**20, "MiB"), "blob_bytes": ("blob store", 1 / 2**20, "MiB"),
         "measurements": ("measurement rows", 1, ""), "js_heap_used": ("console JS heap after GC", 1 / 2**20, "MiB"),
         "dom_nodes": ("console DOM nodes", 1, ""), "js_listeners": ("console JS listeners", 1, ""),
         "api_p99_ms": ("API p99 per sample", 1, "ms")}


def fmt(v, scale=1.0) -> str:
    if v is None:
        return "–"
    v *= scale
    return f"{v:.0f}" if abs(v) >= 100 else f"{v:.1f}" if abs(v) >= 1 else f"{v:.2f}"


def kept_cell(kill: dict) -> str:
    """What a kill left committed, as found at its night's end (ledger.check_kills)."""
    check = kill.get("kept_check")
    if check is None:
        return "not checked" + (f" ({kill['kept_error']})" if kill.get("kept_error") else "")
    return f"all {check['rows']}" if not check["changed"] else f"{check['rows']}, {len(check['changed'])} runs changed"


def main(out: Path) -> int:
    s = json.loads((out / "summary.json").read_text())
    nights = json.loads((out / "nights.json").read_text())["nights"]
    print("| series | unit | night 1 max | later nights' max (high-water mark) | spread of those | "
          "per simulated night | per wall hour (after night 1) |")
    print("|---|---|---|---|---|---|---|")
    for key, (name, scale, unit) in UNITS.items():
        g = s["growth"]["series"].get(key)
        if not g:
            continue
        mx = {int(n): v for n, v in g["max_by_night"].items()}
        later = " / ".join(fmt(v, scale) for n, v in sorted(mx.items()) if n >= 2)
        pct = g.get("flat_spread_pct")
        print(f"| {name} | {unit} | {fmt(mx.get(1), scale)} | {later} | {'–' if pct is None else f'{pct:.1f} %'} | "
              f"{fmt(g['per_night'], scale)} | {fmt(g['per_wall_hour'], scale)} |")
    for key in ("db_bytes", "blob_bytes"):
        per = s["growth"]["series"][key].get("bytes_per_row_by_night") or {}
        print(f"\n{UNITS[key][0]}, bytes per measurement row kept at each night's end: "
              + " / ".join(f"{v:.0f}" for _n, v in sorted(per.items(), key=lambda kv: int(kv[0]))))
    print()
    print("| night | wall | kills (s after start: item) | state | rows | runs equal to night 1 (rows + shape) | "
          "committed at the kills, found unchanged at the end (rows) |")
    print("|---|---|---|---|---|---|---|")
    by = {c["night"]: c for c in s["checks"]["nights"]}
    for n in nights:
        kills = ", ".join(f"{k['at_s']:.0f} s: {k.get('item') or 'between items'}"
                          + (f" ({k['execution_step']})" if k.get("execution_step") else "") for k in n["kills"]) or "–"
        if n.get("missed_kills"):
            kills += "; drawn but after the night's end: " + ", ".join(f"{t:.0f} s" for t in n["missed_kills"])
        c = by.get(n["night"], {})
        kept = " + ".join(kept_cell(k) for k in n["kills"]) or "–"
        print(f"| {n['night']} | {n['wall_s']:.0f} s | {kills} | {n['state']} | {c.get('rows')} | "
              f"{c.get('runs_equal_to_night_1')} of {c.get('runs')} | {kept} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1])))
