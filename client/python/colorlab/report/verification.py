"""verify runs (issue 23, docs/verify.md "Report"): a rendering beside the measured scene, as the verification
stored it — the verdict and its summary (where the renderer is wrong, by how much, where the measurement cannot
tell), false-colour maps, the per-patch and per-spot tables with each comparison's k = 2 band and verdict, and
chapter 8's question (an RGB renderer against a spectral one under each lamp) from the chart-read's spectra.

Nothing is recomputed: every number is the stored one (``data-value`` at full precision). Every string a run or a
client can set (the rendering's name, run ids, patch and spot names, budget sources) goes through ``esc``.
"""
from __future__ import annotations

from . import chapter8, fetch
from . import verification_data as vd
from . import verification_maps as maps
from . import verification_overlay as overlay
from . import verification_photo as photos
from .html import cell, esc, figure

PATCH_KINDS = ("colour_7_3", "colour_7_4")
LIGHT_KINDS = ("light_spot", "light_floor")


def link(client, runs) -> None:
    """Each verify run's chart-read for chapter 8: one of the report's runs, else one of the runs it was checked
    against, or the chart-read a characterize-camera among them was fitted to (fetched)."""
    reads = [r for r in runs if fetch.kind_of(r) == "chart-read"]
    for run in runs:
        if fetch.kind_of(run) != "verify":
            continue
        against = [str(a) for a in (run.doc.get("params") or {}).get("against") or []]
        here = {r.id: r for r in runs}
        run.extra["against_here"] = [a for a in against if a in here]
        found = next((r for r in reads if r.id in against), None) or (reads[0] if reads else None)
        if found is None and client is not None:
            found = _chart_read_of(client, against)
        run.extra["chart_read"] = found
        run.extra["photos"] = photos.load(client, run, vd.by_kind(vd.comparisons(run)))


def _chart_read_of(client, against):
    for rid in against:
        try:
            doc = dict(client.run(rid))
            if doc.get("campaign") == "chart-read":
                return fetch.load(client, rid)
            ref = (doc.get("params") or {}).get("reference_run")
            if doc.get("campaign") == "characterize-camera" and ref:
                return fetch.load(client, ref)
        except Exception:  # noqa: BLE001 — chapter 8 then says it has no spectra; the verification stands alone
            continue
    return None


def _num(v, digits=3):
    return "—" if v is None else f"{v:.{digits}f}"


def _text(value, css="label", **data) -> str:
    attrs = "".join(f' data-{k}="{esc(v)}"' for k, v in data.items())
    return f'<td class="{css}"{attrs}>{esc(value)}</td>'


def _verdict(c) -> str:
    v = str(c.get("verdict"))
    return _text(v, css=f"label verdict-{esc(v)}", verdict=v)


def _table(table_id, caption, head, rows, note="") -> str:
    return (f'<div class="section-table"><table id="{esc(table_id)}"><caption>{esc(caption)}</caption><thead><tr>'
            + "".join(f'<th class="label">{esc(h)}</th>' for h in head) + "</tr></thead><tbody>" + "".join(rows)
            + "</tbody></table></div>" + (f'<p class="note">{note}</p>' if note else ""))


def _vec(values, digits=2) -> str:
    return ", ".join(_num(v, digits) for v in values or [])


def header(run, s) -> str:
    p = run.doc.get("params") or {}
    verdict = str(s.get("verdict", ""))
    against = []
    for a in p.get("against") or []:
        short = "r" + str(a).replace("-", "")[-12:]
        against.append(f'<a href="#{esc(short)}">{esc(a)}</a>' if a in run.extra.get("against_here", []) else esc(a))
    scale = p.get("scale")
    scales = s.get("scales") or []
    how = "; ".join(f"{esc(x.get('kind'))}: {esc(x.get('how'))} ({_num(x.get('factor'), 4)})" for x in scales)
    return (f'<p data-verdict="{esc(verdict)}" id="{run.short}-verdict"><b>Verdict: {esc(verdict)}</b> '
            f'(k = {esc(p.get("k", s.get("coverage_k", 2)))}) — rendering <code>{esc(p.get("rendering", "?"))}</code> '
            f'against {", ".join(against) or "—"}. Scale: '
            + (f"given, {esc(scale)} renderer unit → cd/m²" if scale is not None else "fitted per kind (a fitted "
               "factor cannot see a lamp that is uniformly too bright)")
            + (f"; used: {how}" if how else "") + ". " + noise_note(run, p) + "</p>")


# How a stored verification's rendering noise was pooled, by its params' `noise_pooling` (verify/compare/stored.hpp).
POOLING = {"median-screen": "each region screened against the median of its neighbours' levels first, an outlier "
                            "left out of their pool and judged by its own spread"}


def noise_note(run, p) -> str:
    """The rendering-noise source as the stored params say it was made: off, or pooled over how many regions and how
    (a verification stored before `noise_pooling` existed has none: not recorded)."""
    if p.get("rendering_noise") is False:
        return (f'<span id="{run.short}-verify-noise" data-noise-pooling="off">Rendering noise: not in the budget '
                "(the renderer stated its image exact).</span>")
    n = p.get("noise_neighbours", 8)
    pooling = p.get("noise_pooling")
    how = (esc(POOLING.get(pooling, pooling)) if pooling is not None else
           "not recorded (stored before colorlab said it: plain sums over the neighbours if made before "
           "2026-11-29's robust screen, the screen if after)")
    return (f'<span id="{run.short}-verify-noise" data-noise-pooling="{esc(pooling or "not recorded")}">Rendering '
            f"noise: in the budget, its level pooled over the {esc(n if n is not None else 8)} nearest regions of a "
            f"kind; pooling: {how}.</span>")


def summary_table(run, s) -> str:
    rows = []
    for kind, k in (s.get("kinds") or {}).items():
        rel = vd.is_relative(kind)
        scale = 100.0 if rel else 1.0
        worst = k.get("worst") or {}
        key = esc(kind)
        vals = [("compared", k.get("compared"), 0), ("agree", k.get("agree"), 0), ("differ", k.get("differ"), 0),
                ("agree %", None if k.get("agree_fraction") is None else 100 * k["agree_fraction"], 1),
                ("median |difference|", None if k.get("median_abs_difference") is None
                 else scale * k["median_abs_difference"], 2),
                ("worst", None if worst.get("difference") is None else scale * worst["difference"], 2),
                ("its band", None if worst.get("expanded") is None else scale * worst["expanded"], 2)]
        rows.append(f'<tr data-row="{key}">' + _text(vd.KIND_NAMES.get(kind, kind)) + _text("%" if rel else "ΔE00")
                    + "".join(cell(v, row=kind, col=name, digits=d) for name, v, d in vals)
                    + _text(worst.get("where", "—"), where=worst.get("where", "")) + "</tr>")
    return _table(f"{run.short}-verify-summary", "Summary per kind of comparison",
                  ["kind", "unit", "compared", "agree", "differ", "agree %", "median |difference|", "worst",
                   "its band (k = 2)", "worst at"], rows,
                  "Issue 23's bound for a faithful rendering: ≥ 95 % agree. Relative differences in %.")


def wrong_and_blind(run, s, items_of=None) -> str:
    items_of = items_of or {}
    out = []
    for kind, k in (s.get("kinds") or {}).items():
        rel = vd.is_relative(kind)
        unit = " %" if rel else " ΔE00"
        scale = 100.0 if rel else 1.0
        wrong = k.get("renderer_wrong_at") or []
        blind = k.get("measurement_cannot_tell_at") or []
        name = esc(vd.KIND_NAMES.get(kind, kind))
        if wrong:
            items = ", ".join(f'<span data-wrong="{esc(w.get("where"))}">{esc(w.get("where"))}: '
                              f'{_num(scale * w["difference"], 2)}{unit} (band {_num(scale * w["expanded"], 2)})</span>'
                              for w in wrong if w.get("difference") is not None and w.get("expanded") is not None)
            out.append(f"<li><b>Renderer wrong</b> ({name}), {len(wrong)} place(s): {items}.</li>")
        if blind:
            items = ", ".join(f'<span data-blind="{esc(b.get("where"))}">{esc(b.get("where"))} (band '
                              f'{_num(scale * (b.get("expanded") or 0), 2)}{unit}, mostly {esc(b.get("dominant_source"))})'
                              f"</span>" for b in blind)
            out.append(f"<li><b>The measurement cannot tell</b> ({name}), {len(blind)} place(s) whose band is wider "
                       f"than 2{unit} — a renderer error that small would go unseen there: {items}.</li>")
        own = vd.noise_left_out(kind, k, items_of.get(kind, []))
        if own:
            places = ", ".join(f'<span data-noise-left-out="{esc(w)}">{esc(w)}</span>' for w in own)
            out.append(f"<li><b>Rendering noise judged on its own</b> ({name}), {len(own)} place(s): {places} — the "
                       "screen found its pixels' spread beyond what its neighbours' noise explains (a texture, an "
                       "edge, a firefly), so its rendering-noise uncertainty is its own spread alone and it was kept "
                       "out of the others' pooled level.</li>")
    if not out:
        out.append("<li>Every comparison agrees within its k = 2 band, and every band is narrow enough to tell.</li>")
    return f'<ul id="{run.short}-verify-where">' + "".join(out) + "</ul>"


def patch_table(run, kind, items) -> str:
    colour = kind == "colour_7_3"
    rows = []
    for c in items:
        key = f"{kind}/{c['where']}"
        scale = 1.0 if colour else 100.0
        rows.append(f'<tr data-row="{esc(key)}" data-verdict="{esc(c.get("verdict"))}">' + _text(c["where"])
                    + _text(_vec(c.get("rendered"))) + _text(_vec(c.get("measured")))
                    + cell(c["difference"] * scale, row=key, col="difference", digits=3)
                    + cell(None if c.get("expanded") is None else c["expanded"] * scale, row=key, col="expanded", digits=3)
                    + cell(c.get("mahalanobis"), row=key, col="mahalanobis", digits=2)
                    + cell(c.get("threshold"), row=key, col="threshold", digits=2)
                    + _verdict(c) + _text("yes" if c.get("cannot_tell") else "")
                    + _text(vd.dominant(c)) + "</tr>")
    what = ("L*a*b* (the lamp's white)" if colour else "raw counts")
    return _table(f"{run.short}-verify-{kind}", f"Per patch: {vd.KIND_NAMES[kind]}",
                  ["patch", f"rendered {what}", f"measured {what}", "ΔE00" if colour else "|Δ|/|measured|, %",
                   "U (k = 2)", "distance", "threshold", "verdict", "cannot tell", "largest source"], rows,
                  "U is the k = 2 band's half-width along the difference; a comparison differs when its Mahalanobis "
                  "distance exceeds the threshold (the χ² quantile at 95.45 % for its dimension).")


def spot_table(run, kind, items) -> str:
    rows = []
    for c in items:
        key = f"{kind}/{c['where']}"
        r, m = (c.get("rendered") or [None])[0], (c.get("measured") or [None])[0]
        rows.append(f'<tr data-row="{esc(key)}" data-verdict="{esc(c.get("verdict"))}">' + _text(c["where"])
                    + cell(r, row=key, col="rendered", digits=2) + cell(m, row=key, col="measured", digits=2)
                    + cell(1 + c["difference"], row=key, col="ratio", digits=4)
                    + cell(100 * c["difference"], row=key, col="difference", digits=2)
                    + cell(None if c.get("expanded") is None else 100 * c["expanded"], row=key, col="expanded", digits=2)
                    + _verdict(c) + _text("yes" if c.get("cannot_tell") else "") + _text(vd.dominant(c)) + "</tr>")
    return _table(f"{run.short}-verify-{kind}", f"Per spot: {vd.KIND_NAMES[kind]}",
                  ["spot", "rendered cd/m²", "measured cd/m²", "ratio", "difference %", "U (k = 2) %", "verdict",
                   "cannot tell", "largest source"], rows)


def photo_maps(run, kinds) -> list[str]:
    out = []
    shot = run.extra.get("photos") or {}
    if "chart" in shot:
        p = shot["chart"]
        svg = overlay.chart_over_photo(p, kinds, f"{run.short}-verify-chart-photo")
        if svg:
            out.append(figure(f"{run.short}-fig-verify-chart-photo", svg,
                              f"Over the chart photograph (run {esc(p.run_id)}, frame {esc(p.blob[:12])}…, shown in grey): "
                              "each patch's difference in false colour where the chart locator found the patch, placed "
                              f"{esc(overlay.chart_placement(p).how)}; "
                              "outlined in red where it differs beyond the measurement's k = 2 band, a dot where the "
                              "measurement cannot tell.", "verify-chart-photo"))
    if "floor" in shot:
        p = shot["floor"]
        svg = overlay.floor_over_photo(p, kinds, f"{run.short}-verify-floor-photo")
        if svg:
            out.append(figure(f"{run.short}-fig-verify-floor-photo", svg,
                              f"Over the floor photograph ({esc(p.what)} of run {esc(p.run_id)}, shown in grey): the "
                              "luminance ratio rendered / measured as a translucent layer on the floor map's cells, "
                              "the LS-110's measuring discs opaque, placed from the floor's four corners "
                              f"{esc(overlay.floor_placement(p).how)}; outlined "
                              "in red where it differs beyond k = 2, a dot where the measurement cannot tell.",
                              "verify-floor-photo"))
    return out


def section(run) -> str:
    items = vd.comparisons(run)
    s = vd.summary(run, items)
    kinds = vd.by_kind(items)
    out = [header(run, s), summary_table(run, s), wrong_and_blind(run, s, kinds)]
    svg = maps.chart_map(kinds, f"{run.short}-verify-chart-map")
    if svg:
        out.append(figure(f"{run.short}-fig-verify-chart", svg, "The chart as compared: each patch's difference in "
                          "false colour; outlined in red where it differs beyond the measurement's k = 2 band, a dot "
                          "where the measurement cannot tell.", "verify-chart"))
    svg = maps.floor_map(kinds, f"{run.short}-verify-floor-map")
    if svg:
        out.append(figure(f"{run.short}-fig-verify-floor", svg, "Luminance ratio rendered / measured over the floor "
                          "(1 = agree; the floor map's cells are the difference image; the LS-110's spots drawn at "
                          "their places over the measured floor luminance in grey, lighter = brighter): outlined in red where it differs beyond k = 2, a dot where the measurement "
                          "cannot tell.", "verify-floor"))
    out += photo_maps(run, kinds)
    for kind in PATCH_KINDS:
        if kind in kinds:
            out.append(patch_table(run, kind, kinds[kind]))
    for kind in LIGHT_KINDS:
        if kind in kinds:
            out.append(spot_table(run, kind, kinds[kind]))
    out.append(chapter8.section(run, run.extra.get("chart_read")))
    return "\n".join(out)
