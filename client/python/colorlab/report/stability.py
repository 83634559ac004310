"""Stability (issue 11): where each characterization method fails, computed by the report in numpy on the stored
patch values and the reference run's L*a*b*/XYZ.

The issue asks for "the analysis library's stability suite run on the stored data"; colorlab's C++ analysis
library (analysis/) has no stability suite, so its cases are implemented here, and the section says so:
out-of-gamut patches (the largest cross-validated residuals and where they sit), noise (added at the measured
level × k, k = 0..8, refitted), few training patches (learning curve), exposure change (camera values × 0.8 and
× 1.25 before the fitted model is applied) and another lamp than trained under (when the report holds a second
characterize-camera run of the same chart under another lamp).
"""
from __future__ import annotations

import numpy as np

from . import characterization as ch
from . import colour
from . import tradeoff as tr
from .html import esc, figure, table
from .plots import subplots, to_svg

NOISE_K = (0, 1, 2, 3, 4, 5, 6, 7, 8)
EXPOSURES = (0.8, 1.0, 1.25)
POLYS = (1, 6, 10)
DRAWS = 5
SEED = 7


# ---- the methods: fit(rgb01, lab, xyz100) → params; apply(rgb01, params) → L*a*b* --------------------------------

class CameraSpace:
    name, key, params = "camera colour space (Adobe RGB)", "space", 0

    def fit(self, rgb, lab, xyz):
        return None

    def apply(self, rgb, m):
        return colour.adobe_rgb_to_lab(np.clip(rgb, 0, 1))


class MatrixShaper:
    name, key, params = "ICC matrix/shaper (γ 2.2)", "icc", 9

    def fit(self, rgb, lab, xyz):
        lin = np.clip(rgb, 0, None) ** 2.2
        m, *_ = np.linalg.lstsq(lin, xyz / 100.0, rcond=None)
        return m

    def apply(self, rgb, m):
        return colour.xyz_to_lab(np.clip(rgb, 0, None) ** 2.2 @ m)


class Polynomial:
    def __init__(self, n):
        self.n, self.name, self.key = n, f"polynomial {n}", f"poly{n}"
        self.params = len(colour.POLYNOMIALS[n].split())

    def fit(self, rgb, lab, xyz):
        return tr.fit(rgb, lab, self.n)

    def apply(self, rgb, m):
        return tr.apply(rgb, m, self.n)


def methods(with_xyz: bool):
    return [CameraSpace()] + ([MatrixShaper()] if with_xyz else []) + [Polynomial(n) for n in POLYS]


def cv_residuals(method, rgb, lab, xyz, k=10):
    out = np.empty(len(lab))
    for test in tr.folds(len(lab), k):
        train = np.setdiff1d(np.arange(len(lab)), test)
        m = method.fit(rgb[train], lab[train], xyz[train])
        out[test] = tr.delta_e00(method.apply(rgb[test], m), lab[test])
    return out


def measured_noise(rgb, lab) -> tuple[float, str]:
    """The camera's noise on a patch value, from the chart's repeated patches: the pooled standard deviation of
    the camera values of patches whose reference colours agree within ΔE*ab 1 (the SG's repeated neutrals)."""
    groups, used = [], set()
    for i in range(len(lab)):
        if i in used:
            continue
        same = [j for j in range(len(lab)) if j not in used and np.linalg.norm(lab[j] - lab[i]) < 1.0]
        if len(same) >= 2:
            groups.append(rgb[same])
        used.update(same)
    dof = sum(len(g) - 1 for g in groups) * 3
    if not dof:
        return 0.005, "no repeated patches: 0.5 % of full scale assumed"
    sigma = float(np.sqrt(sum(((g - g.mean(0)) ** 2).sum() for g in groups) / dof))
    return sigma, (f"pooled standard deviation of the camera values over {len(groups)} groups of repeated patches "
                   f"(reference within ΔE*ab 1): σ = {sigma:.5f} of full scale")


def inputs(run):
    ref = ch.reference(run)
    if not ref:
        return None
    for fmt in ch.TEST_CASES:
        ids, rgb = ch.patches(run, fmt)
        keep = [k for k, i in enumerate(ids) if i in ref]
        if len(keep) >= 40:
            ids = [ids[k] for k in keep]
            xyz = [ref[i][1] for i in ids]
            return {"fmt": fmt, "ids": ids, "rgb": rgb[keep] / ch.FULL_SCALE[fmt],
                    "lab": np.stack([ref[i][0] for i in ids]),
                    "xyz": np.stack(xyz) if all(x is not None for x in xyz) else np.full((len(ids), 3), np.nan)}
    return None


def analyse(run) -> dict | None:
    d = inputs(run)
    if not d:
        return None
    rgb, lab, xyz = d["rgb"], d["lab"], d["xyz"]
    ms = methods(bool(np.isfinite(xyz).all()))
    rng = np.random.default_rng(SEED)
    chroma = np.hypot(lab[:, 1], lab[:, 2])
    hue = np.degrees(np.arctan2(lab[:, 2], lab[:, 1])) % 360
    vivid = chroma >= np.quantile(chroma, 0.9)
    sigma, sigma_how = measured_noise(rgb, lab)
    res = {"inputs": d, "methods": ms, "chroma": chroma, "hue": hue, "vivid": vivid, "sigma": sigma,
           "sigma_how": sigma_how, "cv": {}, "noise": {}, "curve": {}, "exposure": {}, "lamp": {}}
    n = len(lab)
    sizes_all = [s for s in (10, 12, 15, 20, 25, 30, 40, 50, 60, 80, 100, n - n // 10) if s < n]
    for m in ms:
        res["cv"][m.key] = cv_residuals(m, rgb, lab, xyz)
        noise = []
        for k in NOISE_K:
            errs = []
            for _ in range(DRAWS):
                a = rgb + rng.normal(0, k * sigma, rgb.shape)
                b = rgb + rng.normal(0, k * sigma, rgb.shape)
                errs.append(tr.delta_e00(m.apply(b, m.fit(a, lab, xyz)), lab).mean())
            noise.append(float(np.mean(errs)))
        res["noise"][m.key] = noise
        if m.params:
            sizes = [s for s in sizes_all if s > m.params]
            curve = []
            for s in sizes:
                errs = []
                for _ in range(DRAWS * 2):
                    perm = rng.permutation(n)
                    trn, tst = perm[:s], perm[s:]
                    errs.append(tr.delta_e00(m.apply(rgb[tst], m.fit(rgb[trn], lab[trn], xyz[trn])), lab[tst]).mean())
                curve.append(float(np.mean(errs)))
            res["curve"][m.key] = (sizes, curve)
        fitted = m.fit(rgb, lab, xyz)
        res["exposure"][m.key] = [tr.delta_e00(m.apply(np.clip(rgb * s, 0, 1), fitted), lab) for s in EXPOSURES]
        for other in run.extra.get("other_lamps") or []:
            o = inputs(other)
            if not o or o["fmt"] != d["fmt"]:
                continue
            lamp = (other.doc.get("params") or {}).get("lamp", "?")
            common = [i for i in o["ids"] if i in d["ids"]]
            oi = [o["ids"].index(i) for i in common]
            res["lamp"].setdefault(lamp, {})[m.key] = tr.delta_e00(m.apply(o["rgb"][oi], fitted), o["lab"][oi])
    return res


# ---- the section --------------------------------------------------------------------------------------------------

def section(run) -> str:
    a = analyse(run)
    if not a:
        return ""
    s = run.short
    d, ms = a["inputs"], a["methods"]
    lamp = (run.doc.get("params") or {}).get("lamp", "")
    out = [f'<h3 id="{s}-stability">Stability: where each characterization method fails</h3>',
           f'<p class="note">Computed by the report in numpy on the stored {esc(d["fmt"])} patch values ({len(d["ids"])} '
           "patches) and the reference run's L*a*b* (and XYZ for the matrix/shaper), not by the daemon: colorlab's "
           "analysis library has no stability suite to run, so its cases are implemented here. Errors are ΔE00 "
           f"(CIEDE2000). Random draws are seeded ({SEED}), so a report is reproducible.</p>"]
    # out of gamut
    cols = ["CV mean", "CV mean, most chromatic 10 %", "CV mean, the rest", "CV max", "worst: L*", "worst: C*ab",
            "worst: h°"]
    rows, worst = [], []
    for m in ms:
        e = a["cv"][m.key]
        w = int(np.argmax(e))
        worst.append(f"{m.name}: {d['ids'][w]}")
        rows.append((m.name, [e.mean(), e[a["vivid"]].mean(), e[~a["vivid"]].mean(), e[w], d["lab"][w, 0],
                              a["chroma"][w], a["hue"][w]], "model", m.key))
    out.append(table(f"{s}-stability-gamut", "Out-of-gamut patches: 10-fold cross-validated ΔE00, the most chromatic "
                     "patches against the rest, and where the worst sits", cols, rows, corner="method",
                     note="Worst patch per method: " + esc("; ".join(worst)) + ". The most chromatic 10 % (reference "
                     "C*ab) are the patches nearest the edge of the camera's gamut."))
    fig, axes = subplots(len(ms), ncols=min(len(ms), 5), width=11, height=2.6)
    for ax, m in zip(axes, ms):
        e = a["cv"][m.key]
        sc = ax.scatter(d["lab"][:, 1], d["lab"][:, 2], s=4 + 12 * e, c=e, cmap="viridis")
        ax.set_title(m.name, fontsize=7)
        ax.set_xlabel("a*", fontsize=7)
        ax.figure.colorbar(sc, ax=ax, shrink=0.8)
    axes[0].set_ylabel("b*")
    out.append(_fig(s, "gamut", "Out of gamut: each patch at its reference a*, b*, size and colour its cross-validated "
                    "ΔE00, per method.", fig))
    # noise
    cols = [f"×{k}" for k in NOISE_K]
    rows = [(m.name, a["noise"][m.key], "model", m.key, None, 3) for m in ms]
    out.append(table(f"{s}-stability-noise", "Noise: mean ΔE00 with Gaussian noise at k × the measured level added "
                     "to the camera values fitted and to those applied", cols, rows, corner="method",
                     note=f"Measured level: {esc(a['sigma_how'])}. Each k: {DRAWS} draws, a model fitted on one noisy "
                     "copy of the chart and applied to another, against the reference."))
    fig, (ax,) = subplots(1, width=6.5, height=3.2)
    for m in ms:
        ax.plot(NOISE_K, a["noise"][m.key], "o-", ms=3, label=m.name)
    ax.set_xlabel("noise (× measured level)")
    ax.set_ylabel("mean ΔE00")
    ax.legend(fontsize=6)
    out.append(_fig(s, "noise", "Noise: mean ΔE00 against the noise added, per method.", fig))
    # few training patches
    if a["curve"]:
        sizes = sorted({x for xs, _ in a["curve"].values() for x in xs})
        cols = [str(x) for x in sizes]
        rows = []
        for m in ms:
            if m.key in a["curve"]:
                xs, ys = a["curve"][m.key]
                by = dict(zip(xs, ys))
                rows.append((f"{m.name} ({m.params} parameters)", [by.get(x) for x in sizes], "model", m.key, None, 3))
        out.append(table(f"{s}-stability-learning", "Few training patches: mean ΔE00 on the patches left out, "
                         "against the number trained on", cols, rows, corner="training patches",
                         note=f"{DRAWS * 2} random draws per size (seeded); a method is tried only with more patches "
                              "than it has parameters."))
        fig, (ax,) = subplots(1, width=6.5, height=3.2)
        for m in ms:
            if m.key in a["curve"]:
                ax.plot(*a["curve"][m.key], "o-", ms=3, label=m.name)
        ax.set_yscale("log")
        ax.set_xlabel("training patches")
        ax.set_ylabel("mean ΔE00 on the rest")
        ax.legend(fontsize=6)
        out.append(_fig(s, "learning", "Few training patches: learning curves (ΔE00 on the patches not trained on).", fig))
    # exposure
    cols = [f"mean ×{x:g}" for x in EXPOSURES] + [f"max ×{x:g}" for x in EXPOSURES]
    rows = [(m.name, [e.mean() for e in a["exposure"][m.key]] + [e.max() for e in a["exposure"][m.key]], "model",
             m.key, None, 3) for m in ms]
    out.append(table(f"{s}-stability-exposure", "Exposure change: each model fitted at the exposure photographed, "
                     "applied to the camera values × 0.8 and × 1.25 (clipped at full scale)", cols, rows,
                     corner="method", note="Training error at × 1; a real exposure change also moves the black level "
                     "and clips differently, which scaling the stored values does not show."))
    fig, (ax,) = subplots(1, width=6.5, height=3.2)
    x = np.arange(len(ms))
    for k, sc in enumerate(EXPOSURES):
        ax.bar(x + (k - 1) * 0.27, [a["exposure"][m.key][k].mean() for m in ms], 0.27, label=f"× {sc:g}")
    ax.set_xticks(x, [m.name for m in ms], fontsize=6, rotation=15)
    ax.set_ylabel("mean ΔE00")
    ax.legend(fontsize=6)
    out.append(_fig(s, "exposure", "Exposure change: mean ΔE00 at × 0.8, × 1 and × 1.25, per method.", fig))
    # another lamp
    if a["lamp"]:
        lamps = sorted(a["lamp"])
        cols = [f"{lamp or 'trained'} (CV)"] + [f"{x} mean" for x in lamps] + [f"{x} max" for x in lamps]
        rows = [(m.name, [a["cv"][m.key].mean()] + [a["lamp"][x][m.key].mean() for x in lamps]
                 + [a["lamp"][x][m.key].max() for x in lamps], "model", m.key, None, 3) for m in ms]
        out.append(table(f"{s}-stability-lamp", f"Another lamp: models fitted under {lamp}, applied to the chart "
                         "photographed under another lamp (its own run), against the same reference", cols, rows,
                         corner="method", note="The reference L*a*b* is the chart's under D50 (the chart-read); a "
                         "model that holds under another lamp would need that lamp's white adapted out first."))
        fig, (ax,) = subplots(1, width=6.5, height=3.2)
        x = np.arange(len(ms))
        ax.bar(x - 0.2, [a["cv"][m.key].mean() for m in ms], 0.4, label=f"{lamp} (CV)")
        for k, other in enumerate(lamps):
            ax.bar(x + 0.2 + 0.4 * k / len(lamps), [a["lamp"][other][m.key].mean() for m in ms], 0.4 / len(lamps),
                   label=other)
        ax.set_xticks(x, [m.name for m in ms], fontsize=6, rotation=15)
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
