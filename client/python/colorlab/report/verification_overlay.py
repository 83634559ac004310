"""The verification's maps over the photograph (issue 23's report): each patch's ΔE00 (§7.3; §7.4's relative
difference beside it) in false colour at the patch's place on the chart photograph, where the chart locator found
it; and the luminance ratio rendered / measured as a translucent false-colour layer over the floor photograph —
the floor map's cells and the LS-110's measuring discs where the floor's corners put them. Red outline: differs
beyond the k = 2 band; a black dot: the measurement cannot tell.

Places come from the stored geometry only: the locator's four outer corners of the patch grid (chart_layout.hpp:
A1's, N1's, N10's, A10's, patch pitch 1, patch side 15/19 of it) and the floor's four corners (1200 × 600 mm),
through the photograph's lens calibration when one is known (verification_lens.py), else as a pinhole.
"""
from __future__ import annotations

import numpy as np
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize, TwoSlopeNorm
from matplotlib.patches import Polygon

from . import verification_data as vd
from .plots import subplots, to_svg
from .verification_lens import Placement
from .verification_photo import FLOOR_MM

SG_COLUMNS, SG_ROWS, PATCH_SIDE = 14, 10, 15.0 / 19.0  # the SG's grid (chart_layout.cpp): 15 mm patches, 19 mm pitch
RATIO_ALPHA = 0.6    # the ratio layer over the floor: the photograph shows through
DIFFERS = dict(edgecolor="#d00000", linewidth=1.6)
CHART_CMAP, RATIO_CMAP = "magma_r", "RdBu_r"


def chart_norm(kind, values) -> Normalize:
    """ΔE00 from 0 to at least 3 (the defect size issue 23 resolves), % from 0 to at least 5."""
    return Normalize(0.0, max(3.0 if kind == "colour_7_3" else 5.0, float(np.max(values)) if len(values) else 0.0))


def ratio_norm(ratios) -> TwoSlopeNorm:
    span = max(0.02, float(np.max(np.abs(np.asarray(ratios) - 1)))) if len(ratios) else 0.02
    return TwoSlopeNorm(vcenter=1.0, vmin=1 - span, vmax=1 + span)


def chart_placement(photo) -> Placement:
    """The SG's grid coordinates → the chart photograph's pixels."""
    gw, gh = SG_COLUMNS - 1 + PATCH_SIDE, SG_ROWS - 1 + PATCH_SIDE
    return Placement([(0, 0), (gw, 0), (gw, gh), (0, gh)], photo.corners, photo.lens)


def floor_placement(photo) -> Placement:
    """Floor millimetres → the floor photograph's pixels."""
    w, d = FLOOR_MM
    return Placement([(0, 0), (w, 0), (w, d), (0, d)], photo.corners, photo.lens)


def patch_outline(place, row, col) -> np.ndarray:
    x, y = col - 1.0, row - 1.0
    return place.polygon([(x, y), (x + PATCH_SIDE, y), (x + PATCH_SIDE, y + PATCH_SIDE), (x, y + PATCH_SIDE)])


def _photo_axes(ax, photo, title):
    ax.imshow(photo.grey, cmap="gray", vmin=0.0, vmax=1.0, interpolation="bilinear",
              extent=(-0.5, photo.width - 0.5, photo.height - 0.5, -0.5))
    ax.set_xlim(-0.5, photo.width - 0.5)
    ax.set_ylim(photo.height - 0.5, -0.5)
    ax.set_aspect("equal")
    ax.grid(False)
    ax.set_xlabel("photograph x, px")
    ax.set_ylabel("y, px")
    ax.set_title(title)


def _mark(ax, c, x, y):
    if c.get("cannot_tell"):
        ax.plot([x], [y], marker=".", color="k", ms=3)


def chart_figure(photo, items_by_kind):
    """(figure, [(axes, kind, cmap, norm)]): one panel per colour kind over the chart photograph."""
    kinds = [k for k in ("colour_7_3", "colour_7_4") if any(vd.patch_rc(c["where"]) for c in items_by_kind.get(k, []))]
    if not kinds:
        return None, []
    place = chart_placement(photo)
    aspect = photo.height / photo.width
    fig, axes = subplots(len(kinds), width=5.2 * len(kinds), height=5.2 * aspect + 0.6)
    panels = []
    for ax, kind in zip(axes, kinds):
        scale = 1.0 if kind == "colour_7_3" else 100.0
        placed = [(vd.patch_rc(c["where"]), c) for c in items_by_kind[kind] if vd.patch_rc(c["where"])]
        values = np.array([abs(c["difference"]) * scale for _, c in placed])
        norm, cmap = chart_norm(kind, values), colormaps[CHART_CMAP]
        _photo_axes(ax, photo, "§7.3: ΔE00 over the photograph" if kind == "colour_7_3"
                    else "§7.4: |Δ| / |measured|, % over the photograph")
        for ((r, col), c), v in zip(placed, values):
            outline = patch_outline(place, r, col)
            edge = DIFFERS if c["verdict"] == "differs" else dict(edgecolor="none")
            ax.add_patch(Polygon(outline, closed=True, facecolor=cmap(norm(v)), **edge))
            centre = place([(col - 1.0 + PATCH_SIDE / 2, r - 1.0 + PATCH_SIDE / 2)])[0]
            _mark(ax, c, *centre)
        sm = ScalarMappable(cmap=cmap, norm=norm)
        fig.colorbar(sm, ax=ax, shrink=0.8, label="ΔE00" if kind == "colour_7_3" else "%")
        panels.append((ax, kind, cmap, norm))
    return fig, panels


def _disc(place, x_mm, y_mm, d_mm, n=32) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return place(np.c_[x_mm + d_mm / 2 * np.cos(t), y_mm + d_mm / 2 * np.sin(t)])


def floor_figure(photo, items_by_kind):
    """(figure, [(axes, kind, cmap, norm)]): the ratio rendered / measured over the floor photograph — the floor
    map's cells as a translucent layer, the LS-110's discs (spot_mm across) over it."""
    kinds = [k for k in ("light_floor", "light_spot") if any(vd.spot_rc(c["where"]) for c in items_by_kind.get(k, []))]
    if not kinds:
        return None, []
    place = floor_placement(photo)
    px, py = vd.PITCH_MM
    spot_mm = photo.extra.get("spot_mm", 20.0)
    norm = ratio_norm([1 + c["difference"] for k in kinds for c in items_by_kind[k]])
    cmap = colormaps[RATIO_CMAP]
    aspect = photo.height / photo.width
    fig, axes = subplots(len(kinds), width=5.2 * len(kinds), height=5.2 * aspect + 0.6)
    panels = []
    for ax, kind in zip(axes, kinds):
        _photo_axes(ax, photo, "floor map: rendered / measured" if kind == "light_floor"
                    else "LS-110 spots: rendered / measured")
        for c in items_by_kind[kind]:
            rc = vd.spot_rc(c["where"])
            if not rc:
                continue
            r, col = rc
            colour = cmap(norm(1 + c["difference"]))
            edge = DIFFERS if c["verdict"] == "differs" else dict(edgecolor="none")
            if kind == "light_floor":
                x0, y0 = col * px, r * py
                outline = place.polygon([(x0, y0), (x0 + px, y0), (x0 + px, y0 + py), (x0, y0 + py)])
                ax.add_patch(Polygon(outline, closed=True, facecolor=colour[:3] + (RATIO_ALPHA,), **edge))
            else:
                ax.add_patch(Polygon(_disc(place, (col + 0.5) * px, (r + 0.5) * py, spot_mm), closed=True,
                                     facecolor=colour, **edge))
            centre = place([((col + 0.5) * px, (r + 0.5) * py)])[0]
            _mark(ax, c, *centre)
        sm = ScalarMappable(cmap=cmap, norm=norm)
        fig.colorbar(sm, ax=ax, shrink=0.8, label="luminance ratio rendered / measured")
        panels.append((ax, kind, cmap, norm))
    return fig, panels


def chart_over_photo(photo, items_by_kind, salt) -> str | None:
    fig, _ = chart_figure(photo, items_by_kind)
    return None if fig is None else to_svg(fig, salt)


def floor_over_photo(photo, items_by_kind, salt) -> str | None:
    fig, _ = floor_figure(photo, items_by_kind)
    return None if fig is None else to_svg(fig, salt)
