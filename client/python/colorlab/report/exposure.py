"""dimmer-exposure runs: Tables 7 and 8 (§6.2's end, "which dimmer setting to use") — one chart photograph per
dimmer level with the exposure doubled as the light halves, and the interval length (max − min) of R, G, B over
the ColorChecker SG's 14 dark border patches at each level."""
from __future__ import annotations

import math

import numpy as np

from . import published as pub
from .html import difference, esc, figure, table
from .plots import subplots, to_svg

CHANNELS = ("R", "G", "B")
COLOURS = {"R": "tab:red", "G": "tab:green", "B": "tab:blue"}


def _level_key(level: float) -> str:
    return f"{level:g}"


def settings(run) -> dict:
    """{level: {shutter_s, aperture_f, luminance, formats}} from the run's exposure/D<level> records."""
    out = {}
    for _, m in run.steps("exposure/D").iterrows():
        level = float(m["data.level"])
        formats = {}
        for col in run.measurements.columns:
            if col.startswith("data.formats.") and col.endswith(".values"):
                f = col.split(".")[2]
                values, ids = m.get(col), m.get(f"data.formats.{f}.ids")
                if values is not None and ids is not None and not (isinstance(values, float) and math.isnan(values)):
                    formats[f] = dict(zip(list(ids), np.asarray(values, dtype=float).reshape(-1, 3)))
        out[level] = {"shutter_s": float(m["data.shutter_s"]), "aperture_f": float(m["data.aperture_f"]),
                      "luminance": float(m["data.luminance"]), "formats": formats}
    return dict(sorted(out.items(), reverse=True))


def intervals(run) -> dict:
    """{format: {level: (R, G, B) interval lengths}} as the campaign stored them (interval/<format>/D<level>)."""
    out: dict = {}
    for _, m in run.steps("interval/").iterrows():
        out.setdefault(m["data.format"], {})[float(m["data.level"])] = tuple(float(v) for v in m["data.rgb"])
    return out


def dark_patches(run) -> dict:
    """{format: {level: {id: (R, G, B)}}} from the dark/<format>/D<level>/<id> records."""
    out: dict = {}
    for _, m in run.steps("dark/").iterrows():
        out.setdefault(m["data.format"], {}).setdefault(float(m["data.level"]), {})[m["data.id"]] = \
            tuple(float(v) for v in m["data.rgb"])
    return out


def _published(tbl, label, levels):
    row = tbl.row(label)
    by = dict(zip(tbl.columns, row.cells))
    return [by.get(_level_key(lv)) for lv in levels]


def section(run) -> str:
    st = settings(run)
    iv = intervals(run)
    if not st or not iv:
        return '<p class="warn">This run stored no photographs per dimmer level (exposure/D…, interval/…).</p>'
    levels = list(st)
    columns = [f"{_level_key(lv)} %" for lv in levels]
    # Table 7.
    ap = [st[lv]["aperture_f"] for lv in levels]
    t = [st[lv]["shutter_s"] for lv in levels]
    pap = [None if c is None else float(c) for c in _published(pub.TABLE7, "Aperture", levels)]
    pt = [None if c is None else pub.seconds(c) for c in _published(pub.TABLE7, "Exposure time", levels)]
    stops = [None if a is None or b is None else math.log2(a / b) for a, b in zip(t, pt)]
    lum = [st[lv]["luminance"] for lv in levels]
    rel = [None if not lum[0] else (t[k] * lum[k]) / (t[0] * lum[0]) for k in range(len(levels))]
    out = [table(f"{run.short}-table7", f"Table 7 — camera settings per dimmer level ({pub.TABLE7.ref()})", columns, [
        ("aperture (f-number) measured", ap, "measured", "aperture-measured", None, 1),
        ("aperture published", pap, "published", "aperture-published", None, 1),
        ("aperture difference", difference(ap, pap), "difference", "aperture-diff", None, 1),
        ("exposure time (s) measured", t, "measured", "exposure-measured", None, 4),
        ("exposure time published (s)", pt, "published", "exposure-published", None, 4),
        ("exposure difference (stops)", stops, "difference", "exposure-stops", None, 2),
        ("LS-110 at the floor beside the chart (cd/m²)", lum, "measured", "luminance", None, 1),
        ("light × time relative to the first level", rel, "derived", "exposure-relative", None, 3),
    ], corner="dimmer level", note=(
        "Measured: the settings the campaign gave the camera (lab.camera.configure) for each photograph, the lamp's "
        "stable LS-110 reading at that level. The last row is what the camera received relative to the first level: "
        "1 if the exposure compensated the dimmer exactly; a phase-cut dimmer is not proportional (§6.2), so it "
        "is not."))]
    # Table 8, in the format the dissertation measured (8-bit values) when the run has it.
    fmt8 = "tiff8" if "tiff8" in iv else sorted(iv)[0]
    rows = []
    for k, ch in enumerate(CHANNELS):
        measured = [iv[fmt8].get(lv, (None,) * 3)[k] for lv in levels]
        published = [None if c is None else float(c) for c in _published(pub.TABLE8, ch, levels)]
        rows += [(f"{ch} measured", measured, "measured", f"{ch}-measured"),
                 (f"{ch} published", published, "published", f"{ch}-published"),
                 (f"{ch} difference", difference(measured, published), "difference", f"{ch}-diff")]
    out.append(table(f"{run.short}-table8", f"Table 8 — interval length of R, G, B over the 14 dark border patches, "
                                            f"{fmt8} ({pub.TABLE8.ref()})", columns, rows, corner="dimmer level",
                     note=("Interval length: the largest minus the smallest robust patch value of the 14 dark (black) "
                           "border patches of the ColorChecker SG — C1, F1, I1, L1, C10, F10, I10, L10, A2, A5, A8, N3, "
                           "N6, N9 (the border's repeated black, L* 6.5) — per channel. The dissertation's numbers are "
                           "8-bit values of its 20D's photographs; the measured ones are the run's "
                           f"{esc(fmt8)} values. The dissertation puts its spread down to noise from the longer "
                           "exposures; the simulated camera's noise, averaged over each patch's pixels, and its smooth "
                           "light across the chart leave a spread about ten times smaller." + ("" if fmt8 == "tiff8" else " (The run has no 8-bit TIFF: the "
                                                     "published values compare only in trend.)"))))
    dp = dark_patches(run)
    if "raw" in iv and "raw" in dp:
        raw_rows = []
        for k, ch in enumerate(CHANNELS):
            length = [iv["raw"].get(lv, (None,) * 3)[k] for lv in levels]
            mean = [float(np.mean([v[k] for v in dp["raw"][lv].values()])) if lv in dp["raw"] else None for lv in levels]
            raw_rows += [(f"{ch} interval length", length, "measured", f"{ch}-interval"),
                         (f"{ch} mean of the dark patches", mean, "measured", f"{ch}-mean"),
                         (f"{ch} interval ÷ mean", [None if a is None or not b else a / b for a, b in zip(length, mean)],
                          "derived", f"{ch}-relative", None, 3)]
        out.append(table(f"{run.short}-table8-raw", "Table 8 on the raw (linear counts above black)", columns, raw_rows,
                         corner="dimmer level", note=(
                             "The raw is linear: the interval relative to the dark patches' mean takes out how much "
                             "light each photograph got (the dimmer is not proportional), leaving the spread across "
                             "the chart and the noise.")))
    out.append(figure(f"{run.short}-table8-plot", plot(run, iv, fmt8, levels),
                      "Interval length of R, G, B over the 14 dark border patches against the dimmer level "
                      f"(Table 8): measured ({esc(fmt8)}, solid) beside the dissertation's (dashed).", "Table 8"))
    out.append(patch_details(run, dp, levels))
    return "\n".join(out)


def patch_details(run, dp, levels) -> str:
    parts = []
    for f in sorted(dp):
        ids = sorted({i for lv in dp[f] for i in dp[f][lv]})
        cols = [f"{_level_key(lv)} % {ch}" for lv in levels for ch in CHANNELS]
        rows = [(i, [dp[f].get(lv, {}).get(i, (None,) * 3)[k] for lv in levels for k in range(3)], "measured", i)
                for i in ids]
        parts.append(table(f"{run.short}-dark-{f}", f"Each dark border patch's robust RGB, {f}", cols, rows,
                           corner="patch"))
    return ('<details><summary>Each dark border patch per level (the values Table 8 is made from)</summary>'
            + "\n".join(parts) + "</details>")


def plot(run, iv, fmt8, levels) -> str:
    fig, (ax,) = subplots(1, width=6, height=3.4)
    for k, ch in enumerate(CHANNELS):
        lv = [lv for lv in levels if lv in iv[fmt8]]
        ax.plot(lv, [iv[fmt8][x][k] for x in lv], "o-", color=COLOURS[ch], label=f"{ch} measured")
        pcols = [float(c) for c in pub.TABLE8.columns]
        ax.plot(pcols, pub.TABLE8.row(ch).values(), "s--", color=COLOURS[ch], alpha=0.55, label=f"{ch} published")
    ax.set_xlabel("dimmer level (%)")
    ax.set_ylabel(f"interval length ({'8-bit values' if fmt8 == 'tiff8' else fmt8})")
    ax.set_xticks(sorted(set(levels) | {100, 50, 25, 15}))
    ax.invert_xaxis()
    ax.legend(fontsize=7, ncol=2)
    return to_svg(fig, f"{run.short}-table8-plot")
