"""characterize-camera runs: chapter 7's Tables 9-13 and figs. 51-60, as far as the stored data allows.

What the run stores: each format's 140 patch values (patch/<format>/<id>), the reference L*a*b* and XYZ through
its chart-read run, and its own fits' error statistics (ΔE00 and ΔE*ab mean/max, training and cross-validated;
the black box's residual statistics and curves). Per-patch errors are not stored, so the report computes those
the dissertation's way from the patch values and the reference (colour.py): the camera's colour space (§7.1),
the lab's matrix/shaper profile rebuilt (§7.2) — both checked against the daemon's own ΔE*ab — and the eleven
polynomials of §7.3. Table 13 shows the black box's stored residual statistics (min, median, mean, max, stdev per
channel; runs since issue 11 also store each patch's residual).
"""
from __future__ import annotations

import numpy as np

from . import colour
from . import published as pub
from .html import difference, esc, figure, table
from .plots import subplots, to_svg

FULL_SCALE = {"tiff8": 255.0, "jpeg": 255.0, "tiff16": 65535.0, "raw": 4095.0}
TEST_CASES = ("tiff8", "jpeg", "tiff16")  # the dissertation's order: 8 bit, jpg, 16 bit
STATS = ("Min", "Max", "Median", "Mean", "Stdev")
APPROACHES = ("camera_colour_space", "icc_profile", "adapted_mapping", "black_box")


def patches(run, fmt: str):
    """(ids, rgb as stored) of one format, in the order photographed."""
    p = run.steps(f"patch/{fmt}/")
    if p.empty:
        return [], np.empty((0, 3))
    return list(p["data.id"]), np.stack(p["data.rgb"].to_numpy()).astype(float)


def reference(run):
    """{patch id: (L*a*b*, XYZ)} of the chart-read run the characterization was fitted against."""
    ref = run.extra.get("reference")
    if ref is None or ref.measurements.empty or "data.Lab" not in ref.measurements:
        return None
    m = ref.measurements[ref.measurements["data.Lab"].notna()]
    xyz = m["data.XYZ"] if "data.XYZ" in m else [None] * len(m)
    return {i: (np.asarray(v, float), None if x is None else np.asarray(x, float))
            for i, v, x in zip(m["data.id"], m["data.Lab"], xyz)}


def reference_patches(run, minimum: int) -> dict | None:
    """The first test case (8-bit TIFF, JPEG, 16-bit TIFF) with at least `minimum` patches in the reference run:
    {"fmt", "ids", "rgb" (0-1 of full scale), "lab", "xyz" (None when the reference lacks XYZ)}; None without one."""
    ref = reference(run)
    if not ref:
        return None
    for fmt in TEST_CASES:
        ids, rgb = patches(run, fmt)
        keep = [k for k, i in enumerate(ids) if i in ref]
        if len(keep) >= minimum:
            ids = [ids[k] for k in keep]
            xyz = [ref[i][1] for i in ids]
            return {"fmt": fmt, "ids": ids, "rgb": rgb[keep] / FULL_SCALE[fmt],
                    "lab": np.stack([ref[i][0] for i in ids]),
                    "xyz": np.stack(xyz) if all(x is not None for x in xyz) else None}
    return None


def analyse(run) -> dict:
    """Per-patch ΔE*ab of the camera's colour space and the lab's matrix/shaper profile per test case, and of
    §7.3's polynomials on the 8-bit TIFF."""
    ref = reference(run)
    out = {"space": {}, "icc": {}, "poly": {}, "poly_format": None}
    if not ref:
        return out
    for fmt in TEST_CASES:
        ids, rgb = patches(run, fmt)
        keep = [k for k, i in enumerate(ids) if i in ref]
        if not keep:
            continue
        ids = [ids[k] for k in keep]
        measured = np.stack([ref[i][0] for i in ids])
        reproduced = colour.adobe_rgb_to_lab(rgb[keep] / FULL_SCALE[fmt])
        out["space"][fmt] = {"ids": ids, "measured": measured, "reproduced": reproduced,
                             "de": colour.delta_e76(reproduced, measured)}
        ap = ((run.result.get("formats") or {}).get(fmt) or {}).get("approaches") or {}
        if "icc_profile" in ap and all(ref[i][1] is not None for i in ids):
            fitted = colour.fit_matrix_shaper(rgb[keep] / FULL_SCALE[fmt], np.stack([ref[i][1] for i in ids]),
                                              ap["icc_profile"].get("gamma", 2.2))
            out["icc"][fmt] = {"ids": ids, "measured": measured, "reproduced": fitted,
                               "de": colour.delta_e76(fitted, measured)}
    fmt = next((f for f in TEST_CASES if f in out["space"]), None)
    if fmt:
        ids, rgb = patches(run, fmt)
        s = out["space"][fmt]
        rgb01 = np.stack([rgb[ids.index(i)] for i in s["ids"]]) / FULL_SCALE[fmt]
        out["poly_format"] = fmt
        for n in colour.POLYNOMIALS:
            fitted = colour.fit_polynomial(rgb01, s["measured"], n)
            out["poly"][n] = {"ids": s["ids"], "reproduced": fitted, "de": colour.delta_e76(fitted, s["measured"])}
    return out


def section(run) -> str:
    res = run.result
    formats = res.get("formats") or {}
    a = analyse(run)
    out = []
    if not formats:
        out.append('<p class="warn">This run stored no characterization result.</p>')
    if run.extra.get("reference") is None:
        out.append('<p class="warn">The reference chart-read run is not available: the per-patch ΔE*ab '
                   '(Tables 9, 11, 12 and figs. 51-54, 58-60) cannot be computed.</p>')
    out.append(approaches_table(run, formats))
    out.append(table9(run, a, formats))
    out.append(table10(run, a, formats))
    out += poly_tables(run, a)
    out.append(table13(run, formats))
    out.append(stored_polynomials(run, formats))
    out += figures(run, a, formats)
    return "\n".join(x for x in out if x)


def approaches_table(run, formats) -> str:
    cols = ["training mean ΔE00", "CV mean ΔE00", "CV median ΔE00", "CV p95 ΔE00", "CV max ΔE00", "CV mean ΔE*ab",
            "CV max ΔE*ab"]
    rows = []
    for fmt, f in formats.items():
        for name in APPROACHES:
            ap = (f.get("approaches") or {}).get(name)
            if not ap:
                continue
            t, cv = ap.get("training") or {}, ap.get("cv") or {}
            rows.append((f"{fmt} {name}" + (f" ({ap['method']})" if ap.get("method") else ""),
                         [t.get("mean"), cv.get("mean"), cv.get("median"), cv.get("p95"), cv.get("max"),
                          cv.get("mean_de76"), cv.get("max_de76")], "stored", f"{fmt}-{name}"))
    sel = run.result.get("selected") or {}
    cv = (run.doc.get("params") or {}).get("cv", "")
    note = (f"As the campaign stored them (cross-validation: {esc(cv)}). Selected for use: {esc(sel.get('format'))}, "
            f"{esc((sel.get('model') or {}).get('method'))}, CV mean ΔE00 {sel.get('cv_mean_de00', float('nan')):.3f}. "
            "The dissertation gives no ΔE00 and no cross-validation, so nothing here has a published counterpart."
            ) if sel else ""
    return table(f"{run.short}-approaches", "The four approaches per test case (§7.1-7.4), the lab's own fits",
                 cols, rows, corner="test case, approach", note=note)


def _stats_rows(measured_by_col: dict, ptable, columns, kind="measured"):
    rows = []
    for stat in STATS:
        m = [measured_by_col.get(c, {}).get(stat) for c in columns]
        by = dict(zip(ptable.columns, ptable.row(stat).values()))
        p = [by.get(c) for c in columns]
        rows += [(f"{stat} {kind}", m, kind, f"{stat}-{kind}"), (f"{stat} published", p, "published", f"{stat}-published"),
                 (f"{stat} difference", difference(m, p), "difference", f"{stat}-diff")]
    return rows


def table9(run, a, formats) -> str:
    cols = [f for f in TEST_CASES if f in a["space"]]
    if not cols:
        return ""
    measured = {f: colour.stats(a["space"][f]["de"]) for f in cols}
    rows = _stats_rows(measured, pub.TABLE9, cols)
    stored = [((formats.get(f, {}).get("approaches") or {}).get("camera_colour_space") or {}).get("training", {})
              for f in cols]
    rows += [("Max, the daemon's (lcms)", [s.get("max_de76") for s in stored], "stored", "Max-stored"),
             ("Mean, the daemon's (lcms)", [s.get("mean_de76") for s in stored], "stored", "Mean-stored")]
    return table(f"{run.short}-table9", "Table 9 — ΔE*ab using the camera's colour space (Adobe RGB), 140 patches",
                 cols, rows, corner="statistic",
                 note=f"Published: {esc(pub.TABLE9.ref())}. Measured: computed here from the stored patch values and "
                      "the reference run's L*a*b* (D50); the daemon's own figures, through lcms, are the last rows.")


def table10(run, a, formats) -> str:
    cols = [f for f in TEST_CASES if "icc_profile" in ((formats.get(f) or {}).get("approaches") or {})]
    if not cols:
        return ""
    kind = formats[cols[0]]["approaches"]["icc_profile"].get("kind", "")
    stored = {f: formats[f]["approaches"]["icc_profile"].get("training") or {} for f in cols}
    if all(f in a["icc"] for f in cols):
        rows = _stats_rows({f: colour.stats(a["icc"][f]["de"]) for f in cols}, pub.TABLE10, cols)
        how = ("Measured: the lab's profile rebuilt here (pure gamma, then a least-squares matrix to the reference "
               "XYZ, D50) from the stored patch values; the run keeps only the profile's statistics, its own "
               "figures (through lcms) are the last rows.")
    else:
        rows = _stats_rows({f: {"Max": stored[f].get("max_de76"), "Mean": stored[f].get("mean_de76")} for f in cols},
                           pub.TABLE10, cols, kind="stored")
        how = "Stored only (no reference XYZ to rebuild the profile): min, median and stdev are not stored."
    rows += [("Max, the daemon's (lcms)", [stored[f].get("max_de76") for f in cols], "stored", "Max-stored"),
             ("Mean, the daemon's (lcms)", [stored[f].get("mean_de76") for f in cols], "stored", "Mean-stored")]
    return table(f"{run.short}-table10", "Table 10 — ΔE*ab using an ICC profile, 140 patches (training)", cols, rows,
                 corner="statistic",
                 note=f"Published: {esc(pub.TABLE10.ref())} (GretagMacbeth ProfileMaker). The lab's profile: "
                      f"{esc(kind)}. {how}")


def poly_tables(run, a):
    if not a["poly"]:
        return []
    out = []
    for ptable, ns in ((pub.TABLE11, (1, 2, 3, 4)), (pub.TABLE12, (5, 6, 7, 8, 9, 10, 11))):
        cols = [str(n) for n in ns]
        measured = {str(n): colour.stats(a["poly"][n]["de"]) for n in ns}
        out.append(table(f"{run.short}-{ptable.number.lower().replace(' ', '')}",
                         f"{ptable.number} — ΔE*ab of the adapted mapping, polynomials {ns[0]}-{ns[-1]} "
                         f"({a['poly_format']}, training)", cols, _stats_rows(measured, ptable, cols),
                         corner="statistic",
                         note=f"Published: {esc(ptable.ref())}. Measured: eq. (2)'s least-squares fit from the stored "
                              f"{esc(a['poly_format'])} patch values (scaled to 0-1) straight to the reference L*a*b*, "
                              "evaluated on the same patches, as in the dissertation. Terms: "
                              + esc("; ".join(f"{n}: {colour.POLYNOMIALS[n]}" for n in ns)) + "."))
    return out


def table13(run, formats) -> str:
    bb = ((formats.get("raw") or {}).get("approaches") or {}).get("black_box")
    if not bb or not bb.get("residuals"):
        return ""
    t = bb["residuals"].get("training") or {}
    cols = ["R", "G", "B"]
    measured = {c: {"Min": t.get(c, {}).get("min"), "Max": t.get(c, {}).get("max"),
                    "Median": t.get(c, {}).get("median"), "Mean": t.get(c, {}).get("mean"),
                    "Stdev": t.get(c, {}).get("stdev")} for c in cols}
    missing_min = any(t.get(c, {}).get("min") is None for c in cols)
    return table(f"{run.short}-table13", f"Table 13 — black-box residuals of R, G, B against the RAW "
                 f"({esc(bb['residuals'].get('unit', 'counts'))}, full scale {bb.get('full_scale', 4095):g})",
                 cols, _stats_rows(measured, pub.TABLE13, cols, kind="stored"), corner="statistic",
                 note=f"Published: {esc(pub.TABLE13.ref())}. Stored: the lab's black box ({esc(bb.get('kind', ''))}; "
                      f"{esc(bb.get('spd_note', ''))}), |predicted − measured| counts over the training patches"
                      + ("; this run predates the stored minimum." if missing_min else
                         ", with each patch's signed residual stored beside them."))


def stored_polynomials(run, formats) -> str:
    cols = [str(n) for n in range(1, 12)]
    rows = []
    for fmt, f in formats.items():
        cands = ((f.get("approaches") or {}).get("adapted_mapping") or {}).get("candidates") or []
        by = {(c["method"], c.get("target")): c for c in cands}
        for target in ("lab",):
            tr = [by.get((f"poly:{n}", target), {}).get("training_mean") for n in range(1, 12)]
            cv = [by.get((f"poly:{n}", target), {}).get("cv_mean") for n in range(1, 12)]
            if any(v is not None for v in tr):
                rows += [(f"{fmt} training mean ΔE00", tr, "stored", f"{fmt}-{target}-training"),
                         (f"{fmt} CV mean ΔE00", cv, "stored", f"{fmt}-{target}-cv")]
    if not rows:
        return ""
    return table(f"{run.short}-polynomials-cv", "The lab's own polynomial fits to L*a*b*: training against "
                 "cross-validated error (no published counterpart)", cols, rows, corner="polynomial",
                 note="A polynomial that fits the training patches better but cross-validates worse has started to "
                      "oscillate (§7.3).")


# ---- figures ---------------------------------------------------------------------------------------------------

CASE_NAME = {"tiff8": "8 bit", "jpeg": "jpg", "tiff16": "16 bit"}


def chart_grid(ids, values):
    """Values on the SG's layout: letter = column, number = row (A1 top left)."""
    cols = max(ord(i[0]) - 65 for i in ids) + 1
    rows = max(int(i[1:]) for i in ids)
    g = np.full((rows, cols), np.nan)
    for i, v in zip(ids, values):
        g[int(i[1:]) - 1, ord(i[0]) - 65] = v
    return g


def _fig(run, fid, item, caption, fig):
    return figure(f"{run.short}-{fid}", to_svg(fig, f"{run.short}-{fid}"), caption, item)


def _histograms(run, fid, item, caption, cases):
    fig, axes = subplots(len(cases), width=8, height=2.6)
    top = max(float(s["de"].max()) for s in cases.values())
    for ax, (fmt, s) in zip(axes, cases.items()):
        ax.hist(s["de"], bins=np.arange(0, top + 1, 1), color="tab:blue", edgecolor="k", lw=0.3)
        ax.set_title(CASE_NAME[fmt])
        ax.set_xlabel("ΔE*ab")
    axes[0].set_ylabel("patches")
    return _fig(run, fid, item, caption, fig)


def _chart_maps(run, fid, item, caption, panels):
    fig, axes = subplots(len(panels), width=8, height=3)
    for ax, (name, ids, de) in zip(axes, panels):
        g = chart_grid(ids, de)
        im = ax.imshow(g, cmap="gray", interpolation="nearest")
        ax.set_xticks(range(g.shape[1]), [chr(65 + k) for k in range(g.shape[1])], fontsize=6)
        ax.set_yticks(range(g.shape[0]), [str(k + 1) for k in range(g.shape[0])], fontsize=6)
        ax.grid(False)
        ax.set_title(name, fontsize=8)
        ax.figure.colorbar(im, ax=ax, shrink=0.8, label="ΔE*ab")
    return _fig(run, fid, item, caption, fig)


def _scatter(run, fid, item, caption, s):
    fig, axes = subplots(3, width=8.5, height=2.9)
    for k, (ax, name) in enumerate(zip(axes, ("L*", "a*", "b*"))):
        m, r = s["measured"][:, k], s["reproduced"][:, k]
        ax.scatter(m, r, s=8, c="tab:blue")
        lo, hi = min(m.min(), r.min()), max(m.max(), r.max())
        ax.plot([lo, hi], [lo, hi], "k--", lw=0.8)
        ax.set_xlabel(f"measured {name}")
        ax.set_ylabel(f"reproduced {name}")
    return _fig(run, fid, item, caption, fig)


def figures(run, a, formats):
    out = []
    space = a["space"]
    if space:
        fig, (ax,) = subplots(1, width=8, height=3)
        for fmt, s in space.items():
            ax.plot(range(1, len(s["de"]) + 1), s["de"], ".-", lw=0.6, ms=3, label=CASE_NAME[fmt])
        ax.set_xlabel("patch (order photographed)")
        ax.set_ylabel("ΔE*ab")
        ax.legend(fontsize=7)
        out.append(_fig(run, "fig51", "51", "Fig. 51 — ΔE*ab per patch for the three test cases, camera's colour space.", fig))
    best = min(a["poly"], key=lambda n: a["poly"][n]["de"].mean()) if a["poly"] else None
    for key, name, (fh, fm, fs) in (("space", "camera's colour space", ("52", "53", "54")),
                                    ("icc", "ICC profile", ("55", "56", "57"))):
        cases = a[key]
        if not cases:
            continue
        out.append(_histograms(run, f"fig{fh}", fh, f"Fig. {fh} — histograms of ΔE*ab, {name}.", cases))
        fmt = next(iter(cases))
        s = cases[fmt]
        panels = [(f"{CASE_NAME[fmt]}, {name}", s["ids"], s["de"])]
        if best and key == "space":
            panels.append((f"{CASE_NAME[a['poly_format']]}, polynomial {best}", a["poly"][best]["ids"], a["poly"][best]["de"]))
        out.append(_chart_maps(run, f"fig{fm}", fm, f"Fig. {fm} — ΔE*ab per patch on the chart's layout (bright = large "
                               f"error), {name}" + (f"; beside it the best of §7.3's polynomials ({best})"
                                                     if len(panels) > 1 else "") + ".", panels))
        out.append(_scatter(run, f"fig{fs}", fs, f"Fig. {fs} — measured against reproduced L*, a*, b*, {name} "
                            f"({CASE_NAME[fmt]}).", s))
    if a["poly"]:
        top = max(float(p["de"].max()) for p in a["poly"].values())
        for fid, ns in (("fig58", (1, 2, 3, 4)), ("fig59", (5, 6, 7, 8, 9, 10, 11))):
            fig, axes = subplots(len(ns), ncols=4, width=9, height=2.2)
            for ax, n in zip(axes, ns):
                ax.hist(a["poly"][n]["de"], bins=np.arange(0, top + 1, 1), color="tab:green", edgecolor="k", lw=0.3)
                ax.set_title(f"polynomial {n}", fontsize=8)
                ax.set_xlabel("ΔE*ab", fontsize=7)
            out.append(_fig(run, fid, fid[3:], f"Fig. {fid[3:]} — histograms of ΔE*ab, polynomials {ns[0]}-{ns[-1]} "
                            f"({CASE_NAME[a['poly_format']]}).", fig))
        fig, (ax,) = subplots(1, width=7.5, height=3.2)
        ns = sorted(a["poly"])
        for stat, colr in zip(STATS, ("tab:blue", "tab:red", "tab:orange", "tab:green", "tab:purple")):
            ax.plot(ns, [colour.stats(a["poly"][n]["de"])[stat] for n in ns], "o-", color=colr, label=f"{stat}")
            pubv = pub.TABLE11.row(stat).values() + pub.TABLE12.row(stat).values()
            ax.plot(range(1, 12), pubv, "s--", color=colr, alpha=0.5, ms=3, label=f"{stat} published")
        ax.set_xticks(ns)
        ax.set_xlabel("polynomial")
        ax.set_ylabel("ΔE*ab")
        ax.legend(fontsize=6, ncol=2)
        out.append(_fig(run, "fig60", "60", "Fig. 60 — ΔE*ab statistics per polynomial (solid) beside Tables 11 and "
                        "12 (dashed).", fig))
    bb = ((formats.get("raw") or {}).get("approaches") or {}).get("black_box")
    if bb and bb.get("sensitivities"):
        sens = bb["sensitivities"]
        wl = np.asarray(sens["wavelengths"], float)
        fig, (ax, bx) = subplots(2, width=9, height=3.2)
        for ch, colr in (("R", "tab:red"), ("G", "tab:green"), ("B", "tab:blue")):
            ax.plot(wl, sens[ch], color=colr, label=ch)
            if f"{ch}_low" in sens and f"{ch}_high" in sens:
                ax.fill_between(wl, sens[f"{ch}_low"], sens[f"{ch}_high"], color=colr, alpha=0.15)
        ax.set_xlabel("wavelength (nm)")
        ax.set_ylabel(f"sensitivity ({sens.get('normalised_to', '')})")
        ax.legend(fontsize=7)
        ax.set_title("(a) recovered spectral sensitivities")
        t = (bb.get("residuals") or {}).get("training") or {}
        x = np.arange(3)
        for k, stat in enumerate(("min", "max", "median", "mean", "stdev")):
            bx.bar(x + k * 0.16, [t.get(c, {}).get(stat, np.nan) for c in "RGB"], 0.16, label=stat)
        pubmax = pub.TABLE13.row("Max").values()
        bx.plot(x + 0.16, pubmax, "k_", ms=18, mew=2, label="published max")
        bx.set_xticks(x + 0.32, list("RGB"))
        bx.set_ylabel("residual (counts)")
        bx.legend(fontsize=6)
        bx.set_title("(b) residuals against the RAW")
        out.append(_fig(run, "blackbox", "13", "Black box (§7.4): (a) the spectral sensitivities recovered (bands: the "
                        "range the fit allows), (b) its residuals against the RAW, with Table 13's maxima.", fig))
    return out
