"""cabinet-grid runs: §6.2's luminance maps (figs. 36-46) and Tables 3-6, dimmer proportionality, lamps compared.

The maps are built from the stored readings (L/<lamp>/D<level>/r<row>c<col>); the analyses are the ones the
campaign computed and stored as its result (window standard deviations, best placement, proportionality, lamps),
so the report shows what the lab decided on, not a second opinion. Like the dissertation, the left half measured
is mirrored into the whole floor (the cabinet is symmetric) and the smallest value subtracted.
"""
from __future__ import annotations

import numpy as np

from . import cabinet_spots
from . import published as pub
from .html import difference, esc, figure, slug, table
from .plots import subplots, to_svg

# The dissertation's figure numbers for its own lamps (840 is the lab's TL84).
DIMMER_FIG = {50: "39", 25: "40", 15: "41"}
LAMP_FIGS = {"TL84": ("43", "45"), "CWF": ("44", "46")}
WINDOW_TABLE = {100: "3", 50: "4", 25: "5", 15: "6"}


def _level_key(level) -> str:
    return f"{float(level):g}"


def grids(run) -> dict:
    """{lamp: {level: rows × cols array}} from the stored readings (NaN where a spot was skipped)."""
    m = run.steps("L/")
    if m.empty:
        return {}
    rows = int(m["data.row"].max()) + 1
    cols = int(m["data.col"].max()) + 1
    out: dict = {}
    for (lamp, level), g in m.groupby(["data.lamp", "data.dimmer_percent"], sort=False):
        a = np.full((rows, cols), np.nan)
        a[g["data.row"].astype(int), g["data.col"].astype(int)] = g.value.astype(float)
        out.setdefault(lamp, {})[float(level)] = a
    return out


def mirrored_difference(half: np.ndarray) -> np.ndarray:
    full = np.hstack([half, half[:, ::-1]])
    return full - np.nanmin(full)


def section(run) -> str:
    maps = grids(run)
    if not maps:
        return '<p class="warn">This run stored no luminance readings (L/…): nothing to map.</p>'
    res = run.result
    uni = res.get("uniformity") or {}
    out = []
    if res.get("incomplete"):
        out.append(f'<p class="warn">Incomplete grids (no analysis): {esc(", ".join(res["incomplete"]))}.</p>')
    if res.get("light_changes"):
        out.append(f'<p class="warn">{len(res["light_changes"])} spot(s) were read again after a lamp drifted '
                   '(the run\'s light_changes).</p>')
    out.append(cabinet_spots.section(run))  # fig. 35
    out.append(summary_table(run, maps, uni))
    out.append(window_tables(run, uni, list(maps)))
    out.append(dimmer_table(run, res.get("dimmer_proportionality") or {}))
    out.append(lamps_table(run, res.get("lamps") or []))
    out.append(figures(run, maps, uni, res.get("dimmer_proportionality") or {}))
    return "\n".join(out)


def summary_table(run, maps, uni) -> str:
    cols = ["min", "max", "range", "best window stdev", "best window row", "best window col", "worst window stdev"]
    rows = []
    for lamp, levels in maps.items():
        for level in sorted(levels, reverse=True):
            u = uni.get(lamp, {}).get(_level_key(level))
            if not u:
                continue
            ws = np.array(u["window_stdev"], dtype=float)
            measured = [u["min"], u["max"], u["max"] - u["min"], u["best"]["stdev"], u["best"]["row"], u["best"]["col"],
                        float(ws.max())]
            published = [None] * len(cols)
            if lamp == "D65" and level == 100:
                published[:3] = [pub.D65_MIN.value, pub.D65_MAX.value, pub.D65_RANGE.value]
            if lamp == "D65" and level == 15:
                published[2] = pub.D65_15_RANGE.value
            if lamp == "D65" and int(level) in pub.BEST_WINDOW_STDEV and level == int(level):
                published[3] = pub.BEST_WINDOW_STDEV[int(level)].value
            if level == 100 and lamp in pub.WORST_WINDOW_STDEV:
                published[6] = pub.WORST_WINDOW_STDEV[lamp].value
            key = f"{lamp}-{_level_key(level)}"
            rows.append((f"{lamp} {level:g} % measured", measured, "measured", f"{key}-measured"))
            if any(p is not None for p in published):
                rows.append((f"{lamp} {level:g} % published", published, "published", f"{key}-published"))
                rows.append((f"{lamp} {level:g} % difference", difference(measured, published), "difference",
                             f"{key}-diff"))
    refs = "; ".join(s.ref() for s in (pub.D65_RANGE, pub.D65_15_RANGE, pub.BEST_WINDOW_STDEV[100],
                                        pub.WORST_WINDOW_STDEV["TL84"]))
    return table(f"{run.short}-maps", "Luminance maps (cd/m²): extremes, best placement of the chart, worst window "
                 "(figs. 36-38, 42, 45, 46)", cols, rows, corner="lamp, dimmer",
                 note=f"Published: {esc(refs)}. Windows are the chart's 4 × 5 border-patch grid on the mirrored floor; "
                      "row and column index the window's corner, from the front left.")


def window_tables(run, uni, order) -> str:
    out = []
    # The daemon's result object has its lamps in key order; the run's own order (D65 first by default) reads better.
    for lamp, levels in sorted(uni.items(), key=lambda kv: order.index(kv[0]) if kv[0] in order else len(order)):
        for level_key, u in sorted(levels.items(), key=lambda kv: -float(kv[0])):
            ws = np.array(u["window_stdev"], dtype=float)
            level = float(level_key)
            number = WINDOW_TABLE.get(int(level)) if lamp == "D65" and level == int(level) else None
            ptab = pub.WINDOW_TABLES.get(int(level)) if number else None
            comparable = ptab is not None and ws.shape == (len(ptab.rows), len(ptab.columns))
            rows = []
            columns = [str(j) for j in range(ws.shape[1])]
            best = (u["best"]["row"], u["best"]["col"])
            for i in range(ws.shape[0]):
                css = ["best" if (i, j) == best else "" for j in range(ws.shape[1])]
                rows.append((f"{i} measured", list(ws[i]), "measured", f"{i}-measured", css))
                if comparable:
                    p = ptab.rows[i].values()
                    rows.append((f"{i} published", p, "published", f"{i}-published"))
                    rows.append((f"{i} difference", difference(list(ws[i]), p), "difference", f"{i}-diff"))
            if number:
                caption = f"Table {number} — window standard deviations, D65 at {level:g} % (cd/m²)"
                tid = f"{run.short}-table{number}"
                note = (f"Published: {esc(ptab.ref())}; — marks cells illegible in the dissertation's text."
                        if comparable else
                        f"The dissertation's {esc(ptab.ref())} covers the full 8 × 10 half-floor (5 × 16 windows); this "
                        f"run's {ws.shape[0]} × {ws.shape[1]} windows are other windows, so they are not set beside it.")
            else:
                caption = f"Window standard deviations, {lamp} at {level:g} % (cd/m²)"
                tid = f"{run.short}-windows-{slug(lamp)}-{slug(level_key)}"
                note = ""
            out.append(table(tid, caption, columns, rows, corner="i \\ j", note=note))
    return "\n".join(out)


def dimmer_table(run, prop) -> str:
    levels = sorted({float(k) for per in prop.values() for k in per}, reverse=True)
    if not levels:
        return ""
    columns = [f"{lv:g}" for lv in levels]
    rows = []
    for lamp, per in prop.items():
        measured = [per.get(_level_key(lv), {}).get("max_abs_error") for lv in levels]
        rows.append((f"{lamp} measured", measured, "measured", f"{lamp}-measured"))
        if lamp == "D65":
            published = [pub.DIMMER_MAX_ABS_ERROR[int(lv)].value if lv == int(lv) and int(lv) in pub.DIMMER_MAX_ABS_ERROR
                         else None for lv in levels]
            rows.append(("D65 published", published, "published", "D65-published"))
            rows.append(("D65 difference", difference(measured, published), "difference", "D65-diff"))
    refs = "; ".join(s.ref() for s in pub.DIMMER_MAX_ABS_ERROR.values())
    return table(f"{run.short}-dimmer", "Dimmer proportionality: max |difference map at full − at level × full/level| (cd/m²)",
                 columns, rows, corner="lamp \\ dimmer %", note=f"Published: {esc(refs)}.")


def lamps_table(run, lamps) -> str:
    if not lamps:
        return ""
    cols = ["min", "max", "range", "best window stdev", "worst window stdev"]
    rows = []
    for lp in lamps:
        name = lp["name"]
        measured = [lp["min"], lp["max"], lp["range"], lp["best"]["stdev"], lp["worst_window"]]
        rows.append((f"{name} measured", measured, "measured", f"{name}-measured"))
        w = pub.WORST_WINDOW_STDEV.get(name)
        published = [None, None, None, None, w.value if w else None]
        if name == "D65":
            published[:3] = [pub.D65_MIN.value, pub.D65_MAX.value, pub.D65_RANGE.value]
            published[3] = pub.BEST_WINDOW_STDEV[100].value
        if any(p is not None for p in published):
            rows.append((f"{name} published", published, "published", f"{name}-published"))
            rows.append((f"{name} difference", difference(measured, published), "difference", f"{name}-diff"))
    return table(f"{run.short}-lamps", "Lamps compared at the highest dimmer level (cd/m²)", cols, rows, corner="lamp",
                 note="Published: the dissertation's 840 is the lab's TL84. "
                      + esc("; ".join(s.ref() for s in pub.WORST_WINDOW_STDEV.values())) + ".")


# ---- figures ---------------------------------------------------------------------------------------------------

def _heat(ax, a, title, vmin=None, vmax=None, cmap="viridis", label="cd/m²"):
    im = ax.imshow(a, origin="lower", cmap=cmap, vmin=vmin, vmax=vmax, aspect="equal", interpolation="nearest")
    ax.set_title(title, fontsize=8)
    ax.set_xlabel("column (left wall → right wall)", fontsize=7)
    ax.set_ylabel("row (front → back)", fontsize=7)
    ax.grid(False)
    ax.figure.colorbar(im, ax=ax, shrink=0.8, label=label)


def _fig(run, fid, item, caption, panels, ncols=2, width=8.5, height=2.6):
    fig, axes = subplots(len(panels), ncols=min(ncols, len(panels)), width=width, height=height)
    for ax, draw in zip(axes, panels):
        draw(ax)
    return figure(f"{run.short}-{fid}", to_svg(fig, f"{run.short}-{fid}"), caption, item)


def figures(run, maps, uni, prop) -> str:
    out = []
    first = "D65" if "D65" in maps else next(iter(maps))
    levels = sorted(maps[first], reverse=True)
    top = levels[0]
    diffs = {lv: mirrored_difference(maps[first][lv]) for lv in levels}
    d = diffs[top]
    out.append(_fig(run, "fig36", "36", f"Fig. 36 — luminance difference distribution of {esc(first)} at {top:g} % "
                    f"(max − min = {np.nanmax(d):.2f} cd/m²; the dissertation's D65 at 100 %: {pub.D65_RANGE.text}).",
                    [lambda ax: _heat(ax, d, f"{first} {top:g} %")], ncols=1, width=6, height=3))
    vmax = max(np.nanmax(x) for x in diffs.values())
    panels = [lambda ax, lv=lv: _heat(ax, diffs[lv], f"{first} {lv:g} %", 0, vmax) for lv in levels]
    out.append(_fig(run, "fig37", "37", f"Fig. 37 — {esc(first)} at every dimmer level, one scale.", panels))
    panels = [lambda ax, lv=lv: _heat(ax, diffs[lv], f"{first} {lv:g} %") for lv in levels]
    out.append(_fig(run, "fig38", "38", f"Fig. 38 — {esc(first)} at every dimmer level, each on its own scale.", panels))
    for lv in levels[1:]:
        num = DIMMER_FIG.get(int(lv)) if first == "D65" and lv == int(lv) else None
        fid = f"fig{num}" if num else f"dimmer-{slug(first)}-{slug(_level_key(lv))}"
        scaled = diffs[lv] * top / lv
        err = prop.get(first, {}).get(_level_key(lv), {}).get("error")
        err = np.array(err, dtype=float) if err is not None else diffs[top] - scaled
        out.append(_fig(run, fid, num or "39-41",
                        f"Fig. {num or '39-41 (analogue)'} — (a) {esc(first)} at {lv:g} % scaled by {top / lv:.3g}, "
                        f"(b) the difference to {top:g} % (max |error| {np.nanmax(np.abs(err)):.2f} cd/m²).",
                        [lambda ax, s=scaled, lv=lv: _heat(ax, s, f"{first} {lv:g} % × {top / lv:.3g}"),
                         lambda ax, e=err: _heat(ax, e, f"{top:g} % − scaled", cmap="coolwarm")]))
    wins = {lv: np.array(uni[first][_level_key(lv)]["window_stdev"], dtype=float)
            for lv in levels if _level_key(lv) in uni.get(first, {})}
    if wins:
        panels = [lambda ax, lv=lv: _heat(ax, wins[lv], f"{first} {lv:g} %", cmap="magma", label="stdev cd/m²")
                  for lv in wins]
        out.append(_fig(run, "fig42", "42", f"Fig. 42 — window standard deviations of {esc(first)} per dimmer level "
                        "(the chart is best placed at the darkest cell).", panels))
    for lamp in maps:
        if lamp == first:
            continue
        lv = sorted(maps[lamp], reverse=True)
        fnum, wnum = LAMP_FIGS.get(lamp, (None, None))
        dl = {x: mirrored_difference(maps[lamp][x]) for x in lv}
        panels = [lambda ax, x=lv[0]: _heat(ax, dl[x], f"{lamp} {x:g} %")]
        caption = f"Fig. {fnum or '43/44 (analogue)'} — (a) {esc(lamp)} at {lv[0]:g} %"
        if len(lv) > 1:
            lo, hi = lv[1], lv[0]
            scaled = dl[lo] * hi / lo
            panels += [lambda ax: _heat(ax, dl[lo], f"{lamp} {lo:g} %"),
                       lambda ax: _heat(ax, scaled, f"{lamp} {lo:g} % × {hi / lo:.3g}"),
                       lambda ax: _heat(ax, dl[hi] - scaled, f"{hi:g} % − scaled", cmap="coolwarm")]
            caption += f", (b) at {lo:g} %, (c) at {lo:g} % scaled by {hi / lo:.3g}, (d) the difference of (a) and (c)"
        out.append(_fig(run, f"fig{fnum}" if fnum else f"lamp-{slug(lamp)}", fnum or "43-44", caption + ".", panels))
        if len(lv) > 2:  # figs. 43/44 show two levels, as the dissertation measured; the map of every level
            out.append(_fig(run, f"maps-{slug(lamp)}", "37-38", f"{esc(lamp)} at every dimmer level, each on its own scale.",
                            [lambda ax, x=x: _heat(ax, dl[x], f"{lamp} {x:g} %") for x in lv]))
        w = [(x, np.array(uni[lamp][_level_key(x)]["window_stdev"], dtype=float)) for x in lv[:2]
             if _level_key(x) in uni.get(lamp, {})]
        if w:
            out.append(_fig(run, f"fig{wnum}" if wnum else f"windows-{slug(lamp)}", wnum or "45-46",
                            f"Fig. {wnum or '45/46 (analogue)'} — window standard deviations of {esc(lamp)} at "
                            + ", ".join(f"{x:g} %" for x, _ in w) + ".",
                            [lambda ax, a=a, x=x: _heat(ax, a, f"{lamp} {x:g} %", cmap="magma", label="stdev cd/m²")
                             for x, a in w]))
    return "\n".join(out)
