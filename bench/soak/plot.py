#!/usr/bin/python3
"""The soak's samples as one figure: a grid of the series against wall time, nights shaded alternately, kills (a
change of daemon pid) marked. ``plot.py samples.csv week.png [--title T]``."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

PANELS = (("rss_kb", "daemon RSS", 1 / 1024, "MiB"),
          ("fds", "open descriptors", 1, "count"),
          ("threads", "threads", 1, "count"),
          ("db_bytes", "SQLite file", 1 / 2**20, "MiB"),
          ("wal_bytes", "SQLite WAL", 1 / 2**20, "MiB"),
          ("blob_bytes", "blob store", 1 / 2**20, "MiB"),
          ("measurements", "measurement rows kept", 1, "rows"),
          ("js_heap_used", "console JS heap (after GC)", 1 / 2**20, "MiB"),
          ("dom_nodes", "console DOM nodes", 1, "count"),
          ("api_p99_ms", "API p99 (GET /v1, runs, control, queue)", 1, "ms"))


def plot(csv_path: Path, png: Path, title: str = "") -> None:
    df = pd.read_csv(csv_path)
    minutes = df["wall_s"] / 60
    kills = df.index[df["daemon_pid"].diff().fillna(0) != 0]
    fig, axes = plt.subplots(5, 2, figsize=(12, 15), sharex=True)
    for ax, (col, name, scale, unit) in zip(axes.flat, PANELS):
        y = pd.to_numeric(df[col], errors="coerce") * scale
        ax.plot(minutes, y, marker=".", lw=1, label="all routes" if col == "api_p99_ms" else None)
        if col == "api_p99_ms":  # per route, where the soak timed them apart
            for route in [c for c in df.columns if c.startswith("api_p99_ms_")]:
                ax.plot(minutes, pd.to_numeric(df[route], errors="coerce"), lw=0.8,
                        label=route.removeprefix("api_p99_ms_"))
            if len(ax.get_lines()) > 1:
                ax.legend(fontsize=7, loc="upper left")
                top = max(float(pd.to_numeric(df[c], errors="coerce").max()) for c in df.columns
                          if c.startswith("api_p99_ms"))
                ax.set_ylim(0, top * 1.15)
        ax.set_title(name, fontsize=10)
        ax.set_ylabel(unit)
        ax.set_ylim(bottom=0, top=max(1e-9, float(y.max()) * 1.15) if y.notna().any() else 1)
        for n in sorted(df["night"].unique()):
            span = minutes[df["night"] == n]
            if n >= 1 and n % 2 == 0 and len(span):
                ax.axvspan(span.min(), span.max(), color="0.92", zorder=0)
        for k in kills:
            ax.axvline(minutes[k], color="tab:red", lw=0.8, ls="--")
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("wall minutes (even nights shaded; red: a sample after a kill -9)")
    fig.suptitle(title or "colorlabd soak", fontsize=12)
    fig.tight_layout(rect=(0, 0, 1, 0.98))
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=80)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="plot.py")
    p.add_argument("csv", type=Path)
    p.add_argument("png", type=Path)
    p.add_argument("--title", default="")
    a = p.parse_args(argv)
    plot(a.csv, a.png, a.title)
    return 0


if __name__ == "__main__":
    sys.exit(main())
