"""Speed against accuracy (issue 11): a Pareto chart per method, the cheapest setting that meets a stated rule named.

- frame-average: frames averaged N → noise (the run's stored σN, mean over the CFA channels) against capture time;
  the run stores no per-frame timing, so capture time is the run's own: from its start to its first stored noise
  row (``measured_at``), shared equally by its F frames, times N.
- characterize-camera: (a) every model the run stored (approaches and the adapted mapping's candidates) → its
  stored cross-validated mean ΔE00 against its stored parameter count; (b) fit and apply time are not stored, so
  §7.3's polynomials 1-11 are refitted here in numpy on the stored patch values and timed, with a 10-fold
  cross-validated ΔE00 the report computes itself.
- cabinet-grid (readings > 1 per spot) and luminance-spot: readings averaged per spot n → repeatability (the pooled
  within-spot standard deviation of the stored readings / √n, relative to the mean) against the meter's time per
  reading (the run's wall time over the readings it took; luminance-spot: the median gap between ``measured_at``).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from . import characterization as ch
from . import tradeoff as tr
from .html import esc, figure, table
from .plots import subplots, to_svg

FRAME_RULE = 1.10          # σN ≤ 1.10 × the noise of the most frames the run averaged
CHAR_TOLERANCE = 0.1       # CV mean ΔE00 within 0.1 of the best (the lab's own model-selection tolerance)
REPEATABILITY_RULE = 0.1   # % of the mean luminance
READINGS = (1, 2, 3, 4, 5, 8, 10, 16, 25)
PATCHES = (10, 15, 20, 30, 40, 60, 80, 100)  # training-set sizes tried (more than the model's terms)
PATCH_RULE = 1.10          # mean ΔE00 ≤ 1.10 × the error trained on 9/10 of the chart
LEARNING_DRAWS, LEARNING_SEED = 10, 11


def _seconds(ts) -> float:
    return pd.Timestamp(ts).timestamp()


def _timed(run, rows) -> bool:
    """Whether the run stored what the time axis is made of: its start and its measurements' measured_at."""
    return bool(run.doc.get("started_at")) and "measured_at" in rows and rows.measured_at.notna().all()


def _front_plot(ax, costs, errors, labels, front, chosen, *, xlabel, ylabel, limit=None, logx=False):
    ax.scatter(costs, errors, s=18, c="tab:gray", label="settings")
    fx = [costs[i] for i in front]
    fy = [errors[i] for i in front]
    ax.step(fx, fy, where="post", color="tab:blue", lw=1.2, label="Pareto front")
    ax.scatter(fx, fy, s=24, c="tab:blue", zorder=3)
    for k, i in enumerate(i for i, lab in enumerate(labels) if lab):  # alternate above and below: dense fronts
        ax.annotate(labels[i], (costs[i], errors[i]), fontsize=6, xytext=(3, 3 if k % 2 == 0 else -9),
                    textcoords="offset points")
    if chosen is not None:
        ax.scatter([costs[chosen]], [errors[chosen]], s=90, facecolors="none", edgecolors="tab:red", lw=1.5,
                   zorder=4, label=f"cheapest meeting the rule: {labels[chosen]}")
    if limit is not None:
        ax.axhline(limit, color="tab:red", ls=":", lw=1, label="rule")
    if logx:
        ax.set_xscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=6)


def _front_flags(n, front):
    return ["front" if i in front else "" for i in range(n)]


# ---- frame averaging ---------------------------------------------------------------------------------------------

def frames_data(run):
    """(frames, noise mean over channels, seconds per N, rule limit, chosen index) from the stored run."""
    rows = run.steps("noise/N")
    if rows.empty or not _timed(run, rows):
        return None
    by_n: dict = {}
    for _, m in rows.iterrows():
        by_n.setdefault(int(m.step.split("/")[1][1:]), []).append(float(m.value))
    frames = sorted(by_n)
    noise = [float(np.mean(by_n[n])) for n in frames]
    total = int(run.result.get("frames") or (run.doc.get("params") or {}).get("frames") or frames[-1])
    capture = _seconds(rows.measured_at.min()) - _seconds(run.doc["started_at"])
    per_frame = capture / total
    times = [per_frame * n for n in frames]
    limit = FRAME_RULE * noise[-1]
    return {"frames": frames, "noise": noise, "times": times, "per_frame": per_frame, "total": total,
            "capture": capture, "limit": limit, "front": tr.pareto_front(times, noise),
            "chosen": tr.cheapest_meeting(times, noise, limit), "unit": rows.unit.iloc[0]}


def frames_section(run) -> str:
    d = frames_data(run)
    if not d:
        return ""
    k = d["chosen"]
    flags = _front_flags(len(d["frames"]), d["front"])
    rows = [("noise, mean of channels (" + d["unit"] + ")", d["noise"], "stored", "noise", None, 3),
            ("capture time (s)", d["times"], "measured", "time", None, 4),
            ("on the Pareto front (1 = yes)", [1.0 if f else 0.0 for f in flags], "derived", "front", None, 0)]
    cols = [str(n) for n in d["frames"]]
    note = (f"Rule: σN ≤ {FRAME_RULE:.2f} × σ{d['frames'][-1]} = {d['limit']:.3f} {esc(d['unit'])} (within 10 % of the "
            f"noise floor this run reached). <b data-chosen=\"{d['frames'][k] if k is not None else ''}\">Cheapest N "
            f"meeting it: {d['frames'][k] if k is not None else 'none'}</b>. Noise: the run's stored σN (mean of its "
            "CFA channels). The run stores no signal level (the region's mean), so a rule relative to the signal "
            "(noise ≤ 1 % of it) cannot be applied, and the published 25-frame figure is in another camera's counts "
            "(Table 2's note). "
            f"Time: not stored per frame — the run's capture time, {d['capture']:.3f} s from its start "
            f"to its first stored noise row (measured_at) for {d['total']} frames, is shared equally "
            f"({d['per_frame'] * 1e3:.2f} ms a frame, processing included) and multiplied by N. On the simulated lab "
            "the time is the simulator's (time-scaled), not a real camera's.")
    fig, (ax,) = subplots(1, width=6.5, height=3.2)
    _front_plot(ax, d["times"], d["noise"], [f"N={n}" for n in d["frames"]], d["front"], k,
                xlabel="capture + processing time (s)", ylabel=f"noise ({d['unit']})", limit=d["limit"])
    return (f'<h3 id="{run.short}-speed">Speed against accuracy: frames averaged</h3>'
            + table(f"{run.short}-pareto-frames", "Frames averaged: noise against time (Pareto)", cols, rows,
                    corner="frames averaged", note=note)
            + figure(f"{run.short}-fig-pareto-frames", to_svg(fig, f"{run.short}-fig-pareto-frames"),
                     "Noise against capture time per number of frames averaged; the Pareto front (blue) and the "
                     "cheapest N meeting the rule (red circle).", "pareto-frames"))


# ---- characterization -------------------------------------------------------------------------------------------

def stored_models(run, fmt):
    """[(label, parameters, stored CV mean ΔE00)] of one format: the approaches and every candidate."""
    f = (run.result.get("formats") or {}).get(fmt) or {}
    ap = f.get("approaches") or {}
    out = []
    if "camera_colour_space" in ap:
        out.append(("camera colour space", 0.0, ap["camera_colour_space"]["cv"]["mean"]))
    if "icc_profile" in ap:
        out.append(("ICC matrix/shaper", 10.0, ap["icc_profile"]["cv"]["mean"]))  # 3 × 3 matrix and one gamma
    if "black_box" in ap and (ap["black_box"].get("cv") or {}).get("mean") is not None:
        out.append(("black box", float(ap["black_box"].get("parameters", np.nan)), ap["black_box"]["cv"]["mean"]))
    for c in (ap.get("adapted_mapping") or {}).get("candidates") or []:
        out.append((f"{c['method']}→{c['target']}", float(c["parameters"]), float(c["cv_mean"])))
    return [m for m in out if np.isfinite(m[1])]


def poly_inputs(run):
    """(format, ids, rgb 0-1, reference L*a*b*) of the first test case with a reference, else None."""
    d = ch.reference_patches(run, 30)
    return (d["fmt"], d["ids"], d["rgb"], d["lab"]) if d else None


def refits(rgb01, lab, k: int = 10):
    """Per polynomial: terms, 10-fold CV ΔE00 (mean), training ΔE00 (mean), fit and apply time (s)."""
    out = {}
    for n in sorted(ch.colour.POLYNOMIALS):
        m = tr.fit(rgb01, lab, n)
        out[n] = {"terms": len(ch.colour.POLYNOMIALS[n].split()),
                  "cv": float(tr.cross_validated(rgb01, lab, n, k).mean()),
                  "training": float(tr.delta_e00(tr.apply(rgb01, m, n), lab).mean()),
                  "fit_s": tr.timed(tr.fit, rgb01, lab, n), "apply_s": tr.timed(tr.apply, rgb01, m, n)}
    return out


def characterization_section(run) -> str:
    inp = poly_inputs(run)
    formats = run.result.get("formats") or {}
    fmt = inp[0] if inp else next((f for f in ch.TEST_CASES if f in formats), None)
    out = [f'<h3 id="{run.short}-speed">Speed against accuracy: characterization models</h3>']
    tol = ((formats.get(fmt) or {}).get("approaches") or {}).get("adapted_mapping", {}).get("tolerance_de00",
                                                                                           CHAR_TOLERANCE) if fmt else CHAR_TOLERANCE
    panels = []
    models = stored_models(run, fmt) if fmt else []
    if models:
        labels, params, cv = [m[0] for m in models], [m[1] for m in models], [m[2] for m in models]
        front = tr.pareto_front(params, cv)
        limit = min(cv) + tol
        k = tr.cheapest_meeting(params, cv, limit)
        rows = [(labels[i], [params[i], cv[i], 1.0 if i in front else 0.0], "stored", labels[i]) for i in range(len(models))]
        out.append(table(f"{run.short}-pareto-models", f"Every model the run stored ({fmt}): parameters against "
                         "cross-validated mean ΔE00", ["parameters", "CV mean ΔE00", "Pareto front"], rows,
                         corner="model",
                         note=(f"Stored: the run's approaches and candidates with their cross-validated mean ΔE00 "
                               f"({esc((run.doc.get('params') or {}).get('cv', ''))}) and parameter counts (ICC: 9 "
                               f"matrix entries and the gamma). Rule: CV mean ΔE00 ≤ best + {tol:g} = {limit:.3f} (the "
                               f"lab's model-selection tolerance). <b data-chosen=\"{esc(labels[k]) if k is not None else ''}\">"
                               f"Cheapest meeting it: {esc(labels[k]) if k is not None else 'none'}</b>. The run stores "
                               "no fit or apply times.")))
        panels.append(("stored", params, cv, labels, front, k, limit))
    if inp:
        fmt_p, ids, rgb01, lab = inp
        r = refits(rgb01, lab)
        ns = sorted(r)
        cost = [r[n]["fit_s"] + r[n]["apply_s"] for n in ns]
        cv = [r[n]["cv"] for n in ns]
        front = tr.pareto_front(cost, cv)
        limit = min(cv) + tol
        k = tr.cheapest_meeting(cost, cv, limit)
        cols = ["terms", "fit (ms)", "apply (ms)", "10-fold CV mean ΔE00", "training mean ΔE00", "Pareto front"]
        rows = [(f"polynomial {n}", [float(r[n]["terms"]), r[n]["fit_s"] * 1e3, r[n]["apply_s"] * 1e3, r[n]["cv"],
                                     r[n]["training"], 1.0 if i in front else 0.0], "model", f"poly{n}", None, 4)
                for i, n in enumerate(ns)]
        out.append(table(f"{run.short}-pareto-refits", f"§7.3's polynomials refitted here ({fmt_p}, {len(ids)} patches): "
                         "fit and apply time against cross-validated ΔE00", cols, rows, corner="model",
                         note=(f"Computed by the report (numpy), not stored: eq. (2) least squares from the stored "
                               f"{esc(fmt_p)} patch values (0-1) to the reference L*a*b*; CV: 10 folds by position "
                               "(patch i in fold i mod 10, leave-14-out), ΔE00 (CIEDE2000); times: the median of 7 "
                               f"runs of the fit on all {len(ids)} patches and of applying it to them, on the machine "
                               f"that made the report. Rule: CV mean ΔE00 ≤ best + {tol:g} = {limit:.3f}. "
                               f"<b data-chosen=\"{ns[k] if k is not None else ''}\">Cheapest meeting it: polynomial "
                               f"{ns[k] if k is not None else 'none'}</b>.")))
        panels.append(("refit", cost, cv, [str(n) for n in ns], front, k, limit))
        # Training-set size as the cost: the best-cross-validating polynomial's learning curve.
        best = ns[int(np.argmin(cv))]
        sizes = [s for s in PATCHES if r[best]["terms"] < s < len(ids)] + [len(ids) - len(ids) // 10]
        curve = tr.learning_curve(rgb01, lab, best, sizes, draws=LEARNING_DRAWS, seed=LEARNING_SEED)
        front = tr.pareto_front(sizes, curve)
        limit = PATCH_RULE * curve[-1]
        k = tr.cheapest_meeting(sizes, curve, limit)
        out.append(table(f"{run.short}-pareto-patches", f"Training-set size: polynomial {best} (the best 10-fold CV "
                         "above) trained on n patches, mean ΔE00 on the rest", [str(x) for x in sizes],
                         [("mean ΔE00 on the rest", curve, "model", "error", None, 4),
                          ("on the Pareto front (1 = yes)", [1.0 if i in front else 0.0 for i in range(len(sizes))],
                           "derived", "front", None, 0)], corner="training patches",
                         note=(f"Computed by the report (numpy): {LEARNING_DRAWS} random draws of n patches per size "
                               f"(seeded {LEARNING_SEED}), fitted, evaluated on the patches not drawn. Rule: ≤ "
                               f"{PATCH_RULE:.2f} × the error at {sizes[-1]} patches = {limit:.3f}. "
                               f"<b data-chosen=\"{sizes[k] if k is not None else ''}\">Cheapest training set meeting "
                               f"it: {sizes[k] if k is not None else 'none'} patches</b>.")))
        panels.append(("patches", sizes, curve, [str(x) for x in sizes], front, k, limit))
    if not panels:
        return ""
    fig, axes = subplots(len(panels), ncols=2, width=9, height=3.4)
    for ax, (what, x, y, labels, front, k, limit) in zip(axes, panels):
        if what == "stored":
            _front_plot(ax, x, y, [lb if i in front else "" for i, lb in enumerate(labels)], front, k,
                        xlabel="parameters", ylabel="stored CV mean ΔE00", limit=limit)
            ax.set_yscale("log")
            ax.set_title("(a) stored models", fontsize=8)
        elif what == "refit":
            _front_plot(ax, [v * 1e3 for v in x], y, labels, front, k, xlabel="fit + apply time (ms, numpy)",
                        ylabel="10-fold CV mean ΔE00", limit=limit)
            ax.set_title("(b) polynomials refitted by the report", fontsize=8)
        else:
            _front_plot(ax, x, y, labels, front, k, xlabel="training patches", ylabel="mean ΔE00 on the rest",
                        limit=limit)
            ax.set_yscale("log")
            ax.set_title("(c) training-set size", fontsize=8)
    out.append(figure(f"{run.short}-fig-pareto-models", to_svg(fig, f"{run.short}-fig-pareto-models"),
                      "Characterization: cross-validated ΔE00 against cost, (a) the run's stored models against their "
                      "parameter count, (b) §7.3's polynomials refitted and timed by the report, (c) the best of them "
                      "against the number of training patches; Pareto fronts (blue) "
                      "and the cheapest model within the tolerance (red circle).", "pareto-models"))
    return "\n".join(out)


# ---- luminance --------------------------------------------------------------------------------------------------

def repeatability(groups, readings=READINGS):
    """groups: lists of repeated readings of one spot. (pooled within-spot stdev, grand mean, relative % per n)."""
    groups = [np.asarray(g, float) for g in groups if len(g) >= 2]
    if not groups:
        return None
    dof = sum(len(g) - 1 for g in groups)
    pooled = float(np.sqrt(sum(((g - g.mean()) ** 2).sum() for g in groups) / dof))
    mean = float(np.mean([g.mean() for g in groups]))
    return pooled, mean, [100 * pooled / np.sqrt(n) / mean for n in readings]


def luminance_data(run):
    m = run.measurements
    if m.empty:
        return None
    if "data.readings" in m:  # cabinet-grid with its readings per spot, lamp and level
        g = m[m.step.str.startswith("L/") & m["data.readings"].notna()]
        if not _timed(run, g):
            return None
        groups = [list(r) for r in g["data.readings"]]
        taken = sum(len(x) for x in groups)
        span = _seconds(g.measured_at.max()) - _seconds(run.doc["started_at"]) if taken else 0
        per = span / taken if taken else np.nan
        how = (f"cabinet-grid: {len(groups)} spot × lamp × level records, each with its stored readings; time per "
               f"reading = the run's wall time to its last record ({span:.3f} s) over the {taken} readings stored "
               "(settling, warm-up and drift checks spread in)")
    else:
        r = run.steps("reading/")
        if len(r) < 2 or not _timed(run, r):
            return None
        groups = [list(r.value.astype(float))]
        per = float(np.median(np.diff(sorted(_seconds(t) for t in r.measured_at))))
        how = (f"luminance-spot: {len(r)} repeated readings of one spot (no grid stores repeats here); time per "
               "reading = the median gap between their measured_at")
    rep = repeatability(groups)
    if rep is None:
        return None
    pooled, mean, rel = rep
    times = [per * n for n in READINGS]
    return {"pooled": pooled, "mean": mean, "rel": rel, "times": times, "per": per, "how": how,
            "front": tr.pareto_front(times, rel), "chosen": tr.cheapest_meeting(times, rel, REPEATABILITY_RULE)}


def luminance_section(run) -> str:
    d = luminance_data(run)
    if not d:
        if run.measurements.empty or "data.readings" not in run.measurements:
            return ""
        return ('<p class="note" id="%s-speed">Speed against accuracy: this run took one reading per spot, so its '
                'repeatability cannot be estimated (run it with readings &gt; 1).</p>' % run.short)
    k = d["chosen"]
    cols = [str(n) for n in READINGS]
    rows = [("repeatability (% of mean)", d["rel"], "derived", "repeatability", None, 4),
            ("time (s)", d["times"], "measured", "time", None, 4),
            ("on the Pareto front (1 = yes)", [1.0 if i in d["front"] else 0.0 for i in range(len(cols))],
             "derived", "front", None, 0)]
    note = (f"From the stored readings: {esc(d['how'])}. Repeatability of an n-reading mean = pooled within-spot "
            f"standard deviation ({d['pooled']:.4g} cd/m², n − 1) / √n, relative to the mean ({d['mean']:.4g} cd/m²); "
            f"the √n is the model (independent readings), the standard deviation is measured. Rule: ≤ "
            f"{REPEATABILITY_RULE:g} %. <b data-chosen=\"{READINGS[k] if k is not None else ''}\">Cheapest readings per "
            f"spot meeting it: {READINGS[k] if k is not None else 'none'}</b>.")
    fig, (ax,) = subplots(1, width=6.5, height=3.2)
    _front_plot(ax, d["times"], d["rel"], [f"n={n}" for n in READINGS], d["front"], k, xlabel="time per spot (s)",
                ylabel="repeatability (% of mean)", limit=REPEATABILITY_RULE)
    return (f'<h3 id="{run.short}-speed">Speed against accuracy: readings per spot</h3>'
            + table(f"{run.short}-pareto-readings", "Readings averaged per spot: repeatability against time (Pareto)",
                    cols, rows, corner="readings per spot", note=note)
            + figure(f"{run.short}-fig-pareto-readings", to_svg(fig, f"{run.short}-fig-pareto-readings"),
                     "Luminance: repeatability of a spot's mean against the time its readings take; Pareto front "
                     "(blue), cheapest meeting the rule (red circle).", "pareto-readings"))
