"""The verification's false-colour maps: ΔE00 per patch on the chart's layout, and the luminance ratio rendered /
measured over the floor (the floor map's cells and the LS-110's spots at their places on the 1200 × 600 mm floor).

A comparison that differs beyond its k = 2 band is outlined in red; one whose band is too wide to tell is dotted.
Only what the run stored is drawn; no text from the run reaches the figure except patch and spot names that
match the chart's and the grid's own patterns (A1 … N10, r<row>c<col>), so nothing hostile reaches the SVG.
"""
from __future__ import annotations

import numpy as np
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.colors import TwoSlopeNorm
from matplotlib.patches import Circle, Rectangle

from . import verification_data as vd
from .plots import subplots, to_svg

DIFFERS = dict(edgecolor="#d00000", linewidth=2.0)


def _mark(ax, c, x, y):
    if c.get("cannot_tell"):
        ax.plot([x], [y], marker=".", color="k", ms=3)


def chart_map(items_by_kind: dict, salt: str) -> str | None:
    """ΔE00 (§7.3) and relative difference (§7.4) on the chart's layout, row 1 at the top."""
    kinds = [k for k in ("colour_7_3", "colour_7_4") if k in items_by_kind
             and any(vd.patch_rc(c["where"]) for c in items_by_kind[k])]
    if not kinds:
        return None
    fig, axes = subplots(len(kinds), width=4.6 * len(kinds), height=3.6)
    for ax, kind in zip(axes, kinds):
        placed = [(vd.patch_rc(c["where"]), c) for c in items_by_kind[kind] if vd.patch_rc(c["where"])]
        rows = max(rc[0] for rc, _ in placed)
        cols = max(rc[1] for rc, _ in placed)
        scale = 1.0 if kind == "colour_7_3" else 100.0
        values = np.array([abs(c["difference"]) * scale for _, c in placed])
        top = max(3.0 if kind == "colour_7_3" else 5.0, float(values.max()))
        cmap = colormaps["magma_r"]
        for (rc, c), v in zip(placed, values):
            r, col = rc
            differs = c["verdict"] == "differs"
            ax.add_patch(Rectangle((col - 0.45, r - 0.45), 0.9, 0.9, facecolor=cmap(v / top),
                                   **(DIFFERS if differs else dict(edgecolor="none"))))
            _mark(ax, c, col, r)
        ax.set_xlim(0.4, cols + 0.6)
        ax.set_ylim(rows + 0.6, 0.4)
        ax.set_xticks(range(1, cols + 1), [chr(ord("A") + i) for i in range(cols)])
        ax.set_yticks(range(1, rows + 1))
        ax.set_aspect("equal")
        ax.grid(False)
        ax.set_title("§7.3: ΔE00" if kind == "colour_7_3" else "§7.4: |Δ| / |measured|, %")
        sm = ScalarMappable(cmap=cmap)
        sm.set_clim(0, top)
        fig.colorbar(sm, ax=ax, shrink=0.8, label="ΔE00" if kind == "colour_7_3" else "%")
    return to_svg(fig, salt)


def _floor_axes(ax, title, extent):
    ax.set_xlim(0, extent[0])  # the grid's part of the 1200 × 600 mm floor (§6.2 measures one half)
    ax.set_ylim(0, extent[1])
    ax.set_aspect("equal")
    ax.grid(False)
    ax.set_xlabel("x on the floor, mm (from the left wall)")
    ax.set_ylabel("y, mm (from the open front)")
    ax.set_title(title)


def _measured_floor(items_by_kind: dict) -> dict:
    """{(row, col): measured cd/m²}: the floor map's cells, else the LS-110's readings at its spots."""
    for kind in ("light_floor", "light_spot"):
        cells = {vd.spot_rc(c["where"]): (c.get("measured") or [None])[0] for c in items_by_kind.get(kind, [])}
        cells = {rc: v for rc, v in cells.items() if rc and v is not None and v > 0}
        if cells:
            return cells
    return {}


def floor_map(items_by_kind: dict, salt: str) -> str | None:
    """Luminance ratio rendered / measured = 1 + the stored relative difference, over the floor."""
    kinds = [k for k in ("light_floor", "light_spot") if k in items_by_kind
             and any(vd.spot_rc(c["where"]) for c in items_by_kind[k])]
    if not kinds:
        return None
    ratios = [1 + c["difference"] for k in kinds for c in items_by_kind[k]]
    span = max(0.02, float(np.max(np.abs(np.array(ratios) - 1))))
    norm = TwoSlopeNorm(vcenter=1.0, vmin=1 - span, vmax=1 + span)
    cmap = colormaps["RdBu_r"]
    fig, axes = subplots(len(kinds), ncols=len(kinds), width=5.0 * len(kinds), height=3.8)
    px, py = vd.PITCH_MM
    places = [vd.spot_rc(c["where"]) for k in kinds for c in items_by_kind[k] if vd.spot_rc(c["where"])]
    extent = ((max(c for _, c in places) + 1) * px, (max(r for r, _ in places) + 1) * py)
    underlay = _measured_floor(items_by_kind)
    for ax, kind in zip(axes, kinds):
        if kind == "light_spot":  # the spots over the floor map as measured
            top = max(underlay.values())
            for (r, col), lum in underlay.items():
                ax.add_patch(Rectangle((col * px, r * py), px, py, facecolor=str(0.35 + 0.6 * lum / top),
                                       edgecolor="none"))
        for c in items_by_kind[kind]:
            rc = vd.spot_rc(c["where"])
            if not rc:
                continue
            r, col = rc
            x, y = (col + 0.5) * px, (r + 0.5) * py
            colour = cmap(norm(1 + c["difference"]))
            edge = DIFFERS if c["verdict"] == "differs" else dict(edgecolor="none")
            if kind == "light_floor":  # the map's cell: the difference image
                ax.add_patch(Rectangle((x - px / 2, y - py / 2), px, py, facecolor=colour, **edge))
            else:  # the LS-110's 20 mm measuring spot, drawn larger to be seen
                ax.add_patch(Circle((x, y), 22, facecolor=colour, **edge))
            _mark(ax, c, x, y)
        _floor_axes(ax, "floor map: luminance rendered / measured" if kind == "light_floor"
                    else "LS-110 spots over the measured floor", extent)
        sm = ScalarMappable(cmap=cmap, norm=norm)
        fig.colorbar(sm, ax=ax, shrink=0.85, label="ratio")
    return to_svg(fig, salt)
