"""chart-read, luminance-spot and any other run: a summary table per quantity and one plot."""
from __future__ import annotations

import numpy as np

from .html import esc, figure, table
from .plots import subplots, to_svg


def quantity_table(run) -> str:
    m = run.measurements
    rows = []
    for (q, unit), g in m.groupby(["quantity", "unit"], sort=True):
        v = g.value.astype(float).to_numpy()
        rows.append((f"{q} ({unit})", [len(v), v.min(), np.median(v), v.mean(),
                                        v.std(ddof=1) if len(v) > 1 else None, v.max()],
                     "measured", q))
    return table(f"{run.short}-summary", "Measurements by quantity", ["count", "min", "median", "mean", "stdev", "max"],
                 rows, corner="quantity")


def section(run, kind: str) -> str:
    m = run.measurements
    if m.empty:
        return '<p class="warn">This run stored no measurements.</p>'
    out = [quantity_table(run)]
    if kind == "chart-read" and "data.Lab" in m:
        out.append(figure(f"{run.short}-chart-lab", chart_plot(run), "The chart's patches as read: a* against b* "
                          "coloured by their own sRGB rendering, and L* per patch.", "chart-read"))
    else:
        out.append(figure(f"{run.short}-series", series_plot(run), "Every reading in the order taken.", "series"))
    return "\n".join(out)


def series_plot(run) -> str:
    fig, (ax,) = subplots(1, width=7, height=3)
    for (q, unit), g in run.measurements.groupby(["quantity", "unit"]):
        ax.plot(range(len(g)), g.value.astype(float), "o-", ms=3, label=f"{q} ({unit})")
        mean = g.value.astype(float).mean()
        ax.axhline(mean, ls="--", lw=0.8, color="k")
    ax.set_xlabel("reading")
    ax.legend(fontsize=7)
    return to_svg(fig, f"{run.short}-series")


def _lab_to_srgb(lab: np.ndarray) -> np.ndarray:
    """For the dots' colours only (D50 L*a*b* → sRGB without adaptation is close enough to recognise a patch)."""
    L, a, b = lab.T
    fy = (L + 16) / 116
    f = np.stack([fy + a / 500, fy, fy - b / 200], axis=1)
    xyz = np.where(f > 6 / 29, f ** 3, 3 * (6 / 29) ** 2 * (f - 4 / 29)) * np.array([0.9642, 1.0, 0.8249])
    m = np.array([[3.1339, -1.6169, -0.4906], [-0.9788, 1.9161, 0.0335], [0.0719, -0.2290, 1.4052]])
    rgb = np.clip(xyz @ m.T, 0, 1)
    return np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)


def chart_plot(run) -> str:
    patches = run.measurements[run.measurements["data.Lab"].notna()]
    lab = np.stack(patches["data.Lab"].to_numpy()).astype(float)
    fig, (a, b) = subplots(2, width=8, height=3.4)
    colours = _lab_to_srgb(lab)
    a.scatter(lab[:, 1], lab[:, 2], c=colours, edgecolors="k", linewidths=0.3, s=22)
    a.set_xlabel("a*")
    a.set_ylabel("b*")
    b.bar(range(len(lab)), lab[:, 0], color=colours, edgecolor="k", linewidth=0.2)
    b.set_xlabel("patch (order read)")
    b.set_ylabel("L*")
    return to_svg(fig, esc(f"{run.short}-chart-lab"))
