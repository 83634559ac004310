"""Chapter 8's question in the verification section: which patches a renderer that multiplies colour triples
gets wrong, and by how much, under each of the cabinet's lamps — from the chart-read's measured reflectance
spectra and the lamps' CIE spectra (spectral_vs_rgb.py does the arithmetic).

The dissertation answers it in words and gamut plots (figs. 62-66), not numbers: XYZ is not closed under
component-wise multiplication (§8.2), but products of real surface colours and lamps are "very unlikely to produce
invalid results" (§8.3, fig. 66). That claim is checked here (XYZ products outside the spectral locus); the ΔE00
figures have no published counterpart (it cites Borges [Bor91] and Ward & Eydelberg-Vileshin [WEV02] for error
bounds without quoting them).
"""
from __future__ import annotations

import numpy as np

from . import spectral_vs_rgb as svr
from . import verification_data as vd
from .html import cell, esc, figure
from .plots import subplots, to_svg

WORST = 5
EXACT = 0.01  # ΔE00 below which a lamp's RGB rendering is exact (rounding only)


def spectra(chart_read):
    """(wavelengths, ids, reflectances) of a chart-read run: the first reading of each patch, as the scene export
    takes it; None when the run holds no spectra on one common grid."""
    m = chart_read.measurements
    if m.empty or "data.values" not in m:
        return None
    rows = m[m.quantity == "reflectance_spectrum"]
    seen, ids, values, grid = set(), [], [], None
    for _, r in rows.iterrows():
        pid = str(r.get("data.id") or r.step.split("/", 1)[-1])
        if pid in seen:
            continue
        v = np.asarray(r["data.values"], float)
        g = (float(r["data.first_nm"]), float(r["data.step_nm"]), len(v))
        if grid is None:
            grid = g
        if g != grid:
            return None
        seen.add(pid)
        ids.append(pid)
        values.append(v)
    if not ids:
        return None
    first, step, n = grid
    return first + step * np.arange(n), ids, np.array(values)


def _lamp_rows(res, ids, short):
    rows = []
    for lamp, r in res.items():
        e, x = r["rgb_de00"], r["xyz_de00"]
        worst = ids[int(np.argmax(e))]
        key = esc(lamp)
        vals = [("rgb mean", e.mean(), 2), ("rgb median", float(np.median(e)), 2), ("rgb max", e.max(), 2),
                ("rgb > 1", int((e > 1).sum()), 0), ("rgb > 3", int((e > 3).sum()), 0),
                ("xyz mean", x.mean(), 2), ("xyz max", x.max(), 2), ("xyz invalid", int(r["xyz_invalid"].sum()), 0)]
        rows.append(f'<tr data-row="{key}"><td class="label">{key}</td>'
                    + "".join(cell(v, row=lamp, col=c, digits=d) for c, v, d in vals[:3])
                    + f'<td class="label" data-row="{key}" data-col="rgb worst">{esc(worst)}</td>'
                    + "".join(cell(v, row=lamp, col=c, digits=d) for c, v, d in vals[3:]) + "</tr>")
    head = ["lamp", "RGB: mean ΔE00", "median", "max", "at", "patches > 1", "> 3", "XYZ: mean ΔE00", "max",
            "XYZ products outside the locus"]
    return (f'<div class="section-table"><table id="{short}-ch8-lamps"><caption>Chapter 8: multiplying triples '
            "against multiplying spectra, per lamp</caption><thead><tr>"
            + "".join(f'<th class="label">{esc(h)}</th>' for h in head) + "</tr></thead><tbody>" + "".join(rows)
            + "</tbody></table></div>")


def _worst_rows(res, ids, short):
    rows = []
    for lamp, r in res.items():
        e = r["rgb_de00"]
        if e.max() < EXACT:  # D65: the albedos are D65 colours, nothing to rank
            continue
        for rank, i in enumerate(np.argsort(-e)[:WORST], 1):
            key = f"{lamp}/{ids[i]}"
            rows.append(f'<tr data-row="{esc(key)}"><td class="label">{esc(lamp)}</td><td class="label">{rank}</td>'
                        f'<td class="label">{esc(ids[i])}</td>'
                        + cell(e[i], row=key, col="rgb", digits=2) + cell(r["xyz_de00"][i], row=key, col="xyz", digits=2)
                        + f'<td class="label">{"yes" if r["albedo_out_of_gamut"][i] else ""}</td></tr>')
    head = ["lamp", "rank", "patch", "RGB ΔE00", "XYZ ΔE00", "albedo outside sRGB"]
    return (f'<div class="section-table"><table id="{short}-ch8-worst"><caption>The patches an RGB renderer gets '
            f"most wrong ({WORST} per lamp where it is not exact)</caption><thead><tr>"
            + "".join(f'<th class="label">{esc(h)}</th>' for h in head) + "</tr></thead><tbody>" + "".join(rows)
            + "</tbody></table></div>")


def _all_rows(res, ids, short):
    lamps = list(res)
    rows = []
    for i, pid in enumerate(ids):
        rows.append(f'<tr data-row="{esc(pid)}"><td class="label">{esc(pid)}</td>'
                    + "".join(cell(res[l]["rgb_de00"][i], row=pid, col=f"rgb {l}", digits=2) for l in lamps)
                    + "".join(cell(res[l]["xyz_de00"][i], row=pid, col=f"xyz {l}", digits=2) for l in lamps) + "</tr>")
    head = ["patch"] + [f"RGB {l}" for l in lamps] + [f"XYZ {l}" for l in lamps]
    return (f'<details><summary>Every patch, ΔE00 against the spectral rendering</summary><div class="section-table">'
            f'<table id="{short}-ch8-patches"><thead><tr>' + "".join(f'<th class="label">{esc(h)}</th>' for h in head)
            + "</tr></thead><tbody>" + "".join(rows) + "</tbody></table></div></details>")


def _map(res, ids, short) -> str | None:
    placed = [(vd.patch_rc(p), i) for i, p in enumerate(ids) if vd.patch_rc(p)]
    if not placed:
        return None
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.patches import Rectangle
    rows, cols = max(rc[0] for rc, _ in placed), max(rc[1] for rc, _ in placed)
    top = max(3.0, max(float(r["rgb_de00"].max()) for r in res.values()))
    cmap = colormaps["magma_r"]
    fig, axes = subplots(len(res), ncols=2, width=9.0, height=3.2)
    for ax, (lamp, r) in zip(axes, res.items()):
        for (row, col), i in placed:
            ax.add_patch(Rectangle((col - 0.45, row - 0.45), 0.9, 0.9, facecolor=cmap(r["rgb_de00"][i] / top)))
        ax.set_xlim(0.4, cols + 0.6)
        ax.set_ylim(rows + 0.6, 0.4)
        ax.set_xticks(range(1, cols + 1), [chr(ord("A") + k) for k in range(cols)])
        ax.set_aspect("equal")
        ax.grid(False)
        ax.set_title(f"RGB renderer under {lamp}: ΔE00")  # lamp names are this module's own, never a run's
        sm = ScalarMappable(cmap=cmap)
        sm.set_clim(0, top)
        fig.colorbar(sm, ax=ax, shrink=0.8)
    return to_svg(fig, f"{short}-ch8-map")


def section(run, chart_read) -> str:
    short = run.short
    title = '<h3 id="{0}-ch8">Chapter 8: an RGB renderer against a spectral one, under each lamp</h3>'.format(short)
    got = spectra(chart_read) if chart_read is not None else None
    if got is None:
        return (title + f'<p class="note" id="{short}-ch8-absent">No chart-read with reflectance spectra is in the '
                "report or among the runs this verification was checked against; add one to the report "
                "(<code>colorlab report VERIFY_RUN CHART_READ_RUN</code>) for chapter 8's numbers.</p>")
    wl, ids, refl = got
    res = svr.by_lamp(wl, refl)
    n = len(ids)
    invalid = sum(int(r["xyz_invalid"].sum()) for r in res.values())
    oog = int(res["D65"]["albedo_out_of_gamut"].sum())
    out = [title,
           f'<p class="note">The {n} patches of chart-read <code>{esc(chart_read.id)}</code> ({wl[0]:g}-{wl[-1]:g} nm, '
           f"{len(wl)} bands) lit by each lamp's CIE spectrum (D65; TL84 = F11; CWF = F2; A), three ways: multiplying "
           "spectra and integrating (the reference); a linear-sRGB renderer (the patch's sRGB albedo under D65 with "
           "white = 1, times the lamp's sRGB triple); an XYZ renderer (the patch's XYZ under the equal-energy light "
           "times the lamp's XYZ, §8.1.2). ΔE00 is each against the spectral result, relative to the lamp's white — "
           "which all three reproduce exactly, so the error is the multiplication's alone. Under D65 the RGB "
           f"renderer is exact by construction (its albedos are D65 colours); {oog} of the {n} albedos lie outside "
           "sRGB's gamut and are kept unclipped.</p>",
           _lamp_rows(res, ids, short),
           f'<p class="note" id="{short}-ch8-published" data-invalid="{invalid}" data-products="{n * len(res)}">'
           f"The dissertation beside it: §8.3 (figs. 64-66) expects products of real surface colours and lamps to stay "
           f"valid colours; here {invalid} of {n * len(res)} XYZ products fall outside the spectral locus. It gives no "
           "ΔE figures for either renderer (figs. 62-66 are gamut plots; the error bounds it cites, Borges [Bor91] and "
           "Ward & Eydelberg-Vileshin [WEV02], are not quoted), so the ΔE00 columns have no published counterpart.</p>",
           _worst_rows(res, ids, short)]
    svg = _map(res, ids, short)
    if svg:
        out.append(figure(f"{short}-fig-ch8", svg, "ΔE00 of the linear-sRGB renderer against the spectral one, per "
                          "patch on the chart's layout, one panel per lamp (same scale).", "chapter-8"))
    out.append(_all_rows(res, ids, short))
    return "\n".join(out)
