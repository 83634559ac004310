"""Stability (issue 11): where each characterization method fails — the analysis library's stability suite
(analysis/stability.hpp, ``colorlab analyze stability``) run on the stored data.

The report writes the run's stored patch values (the first test case with a reference: 8-bit TIFF, JPEG, 16-bit TIFF,
scaled to 0-1 of full scale) with the reference run's XYZ and L*a*b* to a chart file, and the same chart photographed
under another lamp (another characterize-camera run of the same reference in the report) to another, runs the suite
on them and shows its tables: training and cross-validated ΔE00, the most chromatic patches held out (out of gamut),
noise, exposure change, few training patches and the other lamp, each case judged against the suite's stated
tolerance, and each method's first failing case.
"""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from . import analyze
from . import characterization as ch
from .html import esc, figure, table
from .plots import subplots, to_svg

METHODS = ("poly:1", "poly:6", "poly:10", "rootpoly:2")  # §7.3's smallest, middle, best; Finlayson's root polynomial
NOISE = (0.001, 0.005, 0.01, 0.02)
EXPOSURES = (0.5, 0.8, 1.25, 2.0)
SIZES = (10, 12, 15, 20, 25, 30, 40, 50, 60, 80, 100)
DRAWS = 5
SEED = 7
KIND_NAMES = {"training": "training", "cross_validated": "cross-validated", "out_of_gamut": "out of gamut",
              "noise": "noise", "exposure": "exposure", "training_patches": "few training patches",
              "other_lamp": "another lamp"}


def label(method: str) -> str:
    kind, _, n = method.partition(":")
    return {"poly": f"polynomial {n}", "rootpoly": f"root-polynomial {n}"}.get(kind, method)


def key(method: str) -> str:
    return method.replace(":", "")


def suite_arguments(d: dict, files: dict) -> list[str]:
    n = len(d["ids"])
    sizes = [s for s in SIZES if s < n] + [n - n // 10]
    args = ["stability", "--train", str(files["train"]), "--methods", ",".join(METHODS), "--target", "xyz",
            "--input-scale", "1", "--saturation", "1", "--noise", ",".join(map(str, NOISE)),
            "--exposures", ",".join(map(str, EXPOSURES)), "--sizes", ",".join(map(str, sorted(set(sizes)))),
            "--draws", str(DRAWS), "--seed", str(SEED), "--per-patch"]
    for lamp, path in files["lamps"]:
        args += ["--other-lamp", f"{lamp}={path}"]
    return args


def analyse(run) -> dict | None:
    d = ch.reference_patches(run, 40)
    if not d:
        return None
    lamps = []
    for other in run.extra.get("other_lamps") or []:
        o = ch.reference_patches(other, 40)
        if o and o["fmt"] == d["fmt"]:
            lamps.append(((other.doc.get("params") or {}).get("lamp", "?"), o))
    with tempfile.TemporaryDirectory(prefix="colorlab-stability-") as tmp:
        tmp = Path(tmp)
        files = {"train": analyze.write_chart(tmp / "train.csv", d["ids"], d["rgb"], d["lab"], d["xyz"]), "lamps": []}
        for k, (lamp, o) in enumerate(lamps):
            if "=" in lamp:
                continue
            files["lamps"].append((lamp, analyze.write_chart(tmp / f"lamp{k}.csv", o["ids"], o["rgb"], o["lab"], o["xyz"])))
        out = analyze.run_json(*suite_arguments(d, files))
    return {"inputs": d, "suite": out, "lamps": [lamp for lamp, _ in files["lamps"]]}


def _cases(a, method, kind):
    return [c for c in a["suite"]["cases"] if c["method"] == method and c["case"] == kind]


def _case(a, method, kind, level=None, lamp=None):
    for c in _cases(a, method, kind):
        if (level is None or c["level"] == level) and (lamp is None or c["label"] == lamp):
            return c
    return None


def _patches(a, method, kind, level=None):
    """{patch id: ΔE00} of one single-evaluation case."""
    return {p["id"]: p["dE00"] for p in a["suite"].get("patches") or []
            if p["method"] == method and p["case"] == kind and (level is None or p["level"] == level)}


def _stat(c, name):
    return None if c is None else c.get(name)


def _num(v):
    """A plotted value: a case not fitted (null) is a gap."""
    return np.nan if v is None else float(v)


# ---- the section --------------------------------------------------------------------------------------------------

def section(run) -> str:
    a = analyse(run)
    if not a:
        return ""
    s = run.short
    d = a["inputs"]
    st = a["suite"]["settings"][0]
    tol, tol_max = st["tolerance_mean"], st["tolerance_max"]
    lamp = (run.doc.get("params") or {}).get("lamp", "")
    out = [f'<h3 id="{s}-stability">Stability: where each characterization method fails</h3>',
           f'<p class="note">The analysis library\'s stability suite (<code>colorlab analyze stability</code>) on the '
           f'stored {esc(d["fmt"])} patch values ({len(d["ids"])} patches, 0-1 of full scale) against the reference '
           "run's XYZ and L*a*b* (D50): each method fitted to XYZ, then driven out of its training gamut, through "
           "noise, an exposure change, few training patches and another lamp. Errors are ΔE00 (CIEDE2000). A case "
           f"<b>fails</b> when no model can be fitted or its mean ΔE00 exceeds {tol:g} or its largest {tol_max:g} "
           "(the dissertation calls ΔE 4-8 acceptable depending on the application, §3.2). Random draws are seeded "
           f"({st['seed']:g}), so a report is reproducible.</p>"]
    methods = [v["method"] for v in a["suite"]["verdicts"]]
    # verdicts
    rows = []
    for v in a["suite"]["verdicts"]:
        rows.append((label(v["method"]), [v["fails"], v["level"] if v["fails"] else None], "verdict", key(v["method"]),
                     None, 4))
    notes = "; ".join(
        f"{label(v['method'])}: " + (f"first fails at {KIND_NAMES.get(v['first_failing_case'], v['first_failing_case'])}"
                                     + (f" {v['label']}" if v["label"] else f" (level {v['level']:g})")
                                     if v["fails"] else "holds in every case") for v in a["suite"]["verdicts"])
    out.append(table(f"{s}-stability-verdicts", "Where each method first fails (the suite's verdict)",
                     ["fails (1 = yes)", "at level"], rows, corner="method", note=esc(notes) + "."))
    # out of gamut
    chroma = np.hypot(d["lab"][:, 1], d["lab"][:, 2])
    hue = np.degrees(np.arctan2(d["lab"][:, 2], d["lab"][:, 1])) % 360
    index = {i: k for k, i in enumerate(d["ids"])}
    cols = ["training mean", "CV mean", "CV max", "out of gamut mean", "out of gamut max", "worst: L*", "worst: C*ab",
            "worst: h°", "fails"]
    rows, worst = [], []
    for m in methods:
        tr, cv = _case(a, m, "training"), _case(a, m, "cross_validated")
        og = _case(a, m, "out_of_gamut")
        per = _patches(a, m, "out_of_gamut")
        w = max(per, key=per.get) if per else None
        k = index.get(w)
        if w is not None:
            worst.append(f"{label(m)}: {w}")
        rows.append((label(m), [_stat(tr, "mean"), _stat(cv, "mean"), _stat(cv, "max"), _stat(og, "mean"),
                                _stat(og, "max"), None if k is None else d["lab"][k, 0],
                                None if k is None else chroma[k], None if k is None else hue[k],
                                _stat(og, "fails")], "model", key(m)))
    out.append(table(f"{s}-stability-gamut", f"Out of gamut: the {int(st['gamut_held_out'])} most chromatic patches "
                     "(reference C*ab) held out and predicted by a model trained on the rest, beside the training and "
                     f"cross-validated ({esc(st['cv'])}) ΔE00", cols, rows, corner="method",
                     note="Worst held-out patch per method: " + esc("; ".join(worst)) + "."))
    fig, axes = subplots(len(methods), ncols=min(len(methods), 5), width=11, height=2.6)
    for ax, m in zip(axes, methods):
        per = _patches(a, m, "cross_validated")
        e = np.array([per.get(i, np.nan) for i in d["ids"]])
        sc = ax.scatter(d["lab"][:, 1], d["lab"][:, 2], s=4 + 12 * np.nan_to_num(e), c=e, cmap="viridis")
        ax.set_title(label(m), fontsize=7)
        ax.set_xlabel("a*", fontsize=7)
        ax.figure.colorbar(sc, ax=ax, shrink=0.8)
    axes[0].set_ylabel("b*")
    out.append(_fig(s, "gamut", "Each patch at its reference a*, b*, size and colour its cross-validated ΔE00, per "
                    "method: the errors grow towards the edge of the gamut.", fig))
    # noise
    levels = sorted({c["level"] for c in a["suite"]["cases"] if c["case"] == "noise"})
    cols = [f"σ {x * 100:g} %" for x in levels]
    rows = [(label(m), [_stat(_case(a, m, "noise", x), "mean") for x in levels], "model", key(m), None, 4)
            for m in methods]
    out.append(table(f"{s}-stability-noise", "Noise: mean ΔE00 of a model fitted on camera values × (1 + σ·z), "
                     "applied to the stored ones", cols, rows, corner="method",
                     note=f"z ~ N(0, 1) per value; {int(st['draws'])} noisy copies per level, their errors pooled; "
                          "values clipped at full scale."))
    fig, (ax,) = subplots(1, width=6.5, height=3.2)
    for m in methods:
        ax.plot([x * 100 for x in levels], [_num(_stat(_case(a, m, "noise", x), "mean")) for x in levels], "o-", ms=3,
                label=label(m))
    ax.set_xlabel("noise σ (% of the value)")
    ax.set_ylabel("mean ΔE00")
    ax.legend(fontsize=6)
    out.append(_fig(s, "noise", "Noise: mean ΔE00 against the noise added, per method.", fig))
    # few training patches
    sizes = sorted({int(c["level"]) for c in a["suite"]["cases"] if c["case"] == "training_patches"})
    if sizes:
        rows = [(label(m), [_stat(_case(a, m, "training_patches", float(x)), "mean") for x in sizes], "model", key(m),
                 None, 3) for m in methods]
        out.append(table(f"{s}-stability-learning", "Few training patches: mean ΔE00 on the patches left out, against "
                         "the number trained on", [str(x) for x in sizes], rows, corner="training patches",
                         note=f"{int(st['draws'])} random draws per size (seeded); a cell without a number: the "
                              "method has more terms than patches to fit them (not fitted: it fails)."))
        fig, (ax,) = subplots(1, width=6.5, height=3.2)
        for m in methods:
            ax.plot(sizes, [_num(_stat(_case(a, m, "training_patches", float(x)), "mean")) for x in sizes], "o-", ms=3,
                    label=label(m))
        ax.set_yscale("log")
        ax.set_xlabel("training patches")
        ax.set_ylabel("mean ΔE00 on the rest")
        ax.legend(fontsize=6)
        out.append(_fig(s, "learning", "Few training patches: learning curves (ΔE00 on the patches not trained on).",
                        fig))
    # exposure
    ks = sorted({c["level"] for c in a["suite"]["cases"] if c["case"] == "exposure"})
    cols = [f"mean ×{x:g}" for x in ks] + [f"max ×{x:g}" for x in ks]
    rows = [(label(m), [_stat(_case(a, m, "exposure", x), "mean") for x in ks]
             + [_stat(_case(a, m, "exposure", x), "max") for x in ks], "model", key(m), None, 3) for m in methods]
    out.append(table(f"{s}-stability-exposure", "Exposure change: each model fitted at the exposure photographed, "
                     "applied to the camera values × k (clipped at full scale), the predicted XYZ ÷ k", cols, rows,
                     corner="method", note="The chart's colours do not change with exposure, the signal does; a real "
                     "exposure change also moves the black level, which scaling the stored values does not show."))
    fig, (ax,) = subplots(1, width=6.5, height=3.2)
    x = np.arange(len(methods))
    width = 0.8 / max(len(ks), 1)
    for j, k in enumerate(ks):
        ax.bar(x - 0.4 + width * (j + 0.5), [_num(_stat(_case(a, m, "exposure", k), "mean")) for m in methods],
               width, label=f"× {k:g}")
    ax.set_xticks(x, [label(m) for m in methods], fontsize=6, rotation=15)
    ax.set_yscale("log")
    ax.set_ylabel("mean ΔE00")
    ax.legend(fontsize=6)
    out.append(_fig(s, "exposure", "Exposure change: mean ΔE00 at each exposure factor, per method.", fig))
    # another lamp
    if a["lamps"]:
        lamps = a["lamps"]
        cols = [f"{lamp or 'trained'} (training)"] + [f"{x} mean" for x in lamps] + [f"{x} max" for x in lamps]
        rows = [(label(m), [_stat(_case(a, m, "training"), "mean")]
                 + [_stat(_case(a, m, "other_lamp", lamp=x), "mean") for x in lamps]
                 + [_stat(_case(a, m, "other_lamp", lamp=x), "max") for x in lamps], "model", key(m), None, 3)
                for m in methods]
        out.append(table(f"{s}-stability-lamp", f"Another lamp: models fitted under {lamp}, applied to the chart "
                         "photographed under another lamp (its own run), against the same reference", cols, rows,
                         corner="method", note="The reference L*a*b* is the chart's under D50 (the chart-read); a "
                         "model that holds under another lamp would need that lamp's white adapted out first."))
        fig, (ax,) = subplots(1, width=6.5, height=3.2)
        ax.bar(x - 0.2, [_num(_stat(_case(a, m, "training"), "mean")) for m in methods], 0.4, label=f"{lamp} (training)")
        for k, other in enumerate(lamps):
            ax.bar(x + 0.2 + 0.4 * k / len(lamps), [_num(_stat(_case(a, m, "other_lamp", lamp=other), "mean"))
                                                    for m in methods],
                   0.4 / len(lamps), label=other)
        ax.set_xticks(x, [label(m) for m in methods], fontsize=6, rotation=15)
        ax.set_yscale("log")
        ax.set_ylabel("mean ΔE00")
        ax.legend(fontsize=6)
        out.append(_fig(s, "lamp", "Another lamp: mean ΔE00 under the lamp trained under and under the other.", fig))
    else:
        out.append(f'<p class="note" id="{s}-stability-lamp-absent">Another lamp: the report holds one '
                   f"characterize-camera run of this chart ({esc(lamp)}); give it a second run under another lamp "
                   "(characterize-camera lamp = TL84, same reference_run) to see a model applied under a lamp it was "
                   "not trained under.</p>")
    return "\n".join(out)


def _fig(short, name, caption, fig):
    fid = f"{short}-fig-stability-{name}"
    return figure(fid, to_svg(fig, fid), caption, f"stability-{name}")
