"""Fig. 35: the measurement spots on the cabinet floor, as a cabinet-grid run stored them.

Each spot is where the run's readings say it is (``data.row``, ``data.col`` of L/<lamp>/D<level>/r<row>c<col>: the
grid's row from the front, its column from the left wall, in spot pitches), numbered in the order the run first
measured it (the operator's walk). The right half, never measured (the cabinet is symmetric), is drawn as the mirror
image the maps use.
"""
from __future__ import annotations

import numpy as np

from .html import esc, figure, table
from .plots import subplots, to_svg


def spots(run) -> list[tuple[int, int, int]]:
    """[(number, row, col)] numbered 1… in the order of each spot's first stored reading."""
    m = run.steps("L/")
    if m.empty:
        return []
    first = m.sort_values("seq").drop_duplicates(["data.row", "data.col"])
    return [(k + 1, int(r), int(c)) for k, (r, c) in enumerate(zip(first["data.row"], first["data.col"]))]


def section(run) -> str:
    numbered = spots(run)
    if not numbered:
        return ""
    rows = max(r for _, r, _ in numbered) + 1
    cols = max(c for _, _, c in numbered) + 1
    fig, (ax,) = subplots(1, width=8.5, height=3.8)
    for n, r, c in numbered:
        ax.plot(c, r, "o", color="tab:blue", ms=13, alpha=0.25)
        ax.text(c, r, str(n), ha="center", va="center", fontsize=7)
        ax.plot(2 * cols - 1 - c, r, "o", color="0.6", ms=9, mfc="none")
    ax.axvline(cols - 0.5, color="k", ls="--", lw=0.8)
    ax.set_xlim(-0.7, 2 * cols - 0.3)
    ax.set_ylim(rows - 0.4, -0.6)  # the front (row 0), where the camera stands, at the top as seen from it
    ax.set_xticks(range(2 * cols))
    ax.set_yticks(range(rows))
    ax.set_xlabel("spot column from the left wall (measured half left of the dashed line; mirrored right)")
    ax.set_ylabel("spot row from the front")
    ax.set_aspect("equal")
    svg = to_svg(fig, f"{run.short}-fig35")
    cells = [(str(n), [r, c], "measured", str(n)) for n, r, c in numbered]
    listing = table(f"{run.short}-fig35-spots", "The spots as stored, numbered in measuring order", ["row", "col"],
                    cells, corner="spot")
    return (figure(f"{run.short}-fig35", svg,
                   f"Fig. 35 — the {len(numbered)} measurement spots on the cabinet floor ({rows} rows × {cols} columns "
                   "of the left half, as this run stored them), numbered in the order they were first measured; open "
                   "circles: the right half, taken as the mirror image (the dissertation's 80 spots are 8 × 10).",
                   "35")
            + f"<details><summary>{esc('Spot numbers, rows and columns')}</summary>{listing}</details>")
