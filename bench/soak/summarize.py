#!/usr/bin/python3
"""Recomputes a soak's conclusions from what it wrote (samples.csv, nights.json, the probes in summary.json) and
redraws its figure: after a change to bench/soak/checks.py or plot.py, or for a week stopped before its end (the
nights run so far are in nights.json as each ends). ``summarize.py OUT_DIR [--png PATH] [--title T]``."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))

from checks import compare_nights, growth  # noqa: E402
from plot import plot  # noqa: E402
from soak import write_json  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="summarize.py")
    p.add_argument("out", type=Path)
    p.add_argument("--png", type=Path)
    p.add_argument("--title", default="")
    a = p.parse_args(argv)
    doc = json.loads((a.out / "nights.json").read_text())
    nights, meta = doc["nights"], doc["meta"]
    csv = a.out / "samples.csv"
    df = pd.read_csv(csv)
    df.loc[df["night"] > len(nights), "night"] = -1  # the idle tail after the last night belongs to no night
    df.to_csv(csv, index=False)
    summary_path = a.out / "summary.json"
    summary = json.loads(summary_path.read_text()) if summary_path.exists() else {"meta": meta}
    summary["checks"] = compare_nights(nights)
    summary["growth"] = growth(csv, time_scale=meta["time_scale"])
    write_json(summary_path, summary)
    plot(csv, a.png or a.out / "week.png", a.title or f"colorlabd soak: {len(nights)} {meta['sequence']} nights, "
         f"time scale {meta['time_scale']:g}, kills on nights {meta['killed_nights']}")
    print(json.dumps(summary["checks"], indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
