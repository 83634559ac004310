"""The appendix's per-patch tables for a characterize-camera run (dissertation appendix E, Tables 16-20), each
patch's value beside the one the dissertation prints for it, with the difference; collapsed, since they are long.

Tables 16-19: each patch's ΔE*ab, computed the way Tables 9-12 are (characterization.analyse: the camera's colour
space and the lab's matrix/shaper profile per test case, §7.3's polynomials on the first test case, from the stored
patch values and the reference run's L*a*b*). Table 20: each patch's signed black-box residual as the run stored it
(predicted − measured counts on the raw, training). The published values are published.TABLE16 … TABLE20, quoted
with their lines; Table 18's printed columns hold polynomials 2-5 (see published.py), so the columns here are
by polynomial, and polynomial 1 has no published per-patch values.
"""
from __future__ import annotations

import numpy as np

from . import characterization
from . import published as pub
from .html import esc, table

CASE_LABEL = {"tiff8": "8 bit", "jpeg": "jpg", "tiff16": "16 bit"}


def _round(v):
    return None if v is None or not np.isfinite(v) else round(float(v), 4)


def patch_table(run, ptable, measured: dict, columns: list, label: dict, note: str, digits: int = 2) -> str:
    """measured: {column: {patch id: value}}; columns are ``holds`` keys of ptable where it has them."""
    heads, keys = [], []
    for c in columns:
        has = c in ptable.holds
        heads += [f"{label[c]} measured"] + ([f"{label[c]} published", f"{label[c]} diff"] if has else [])
        keys.append((c, has))
    published = {c: ptable.column(c) for c, has in keys if has}
    rows = []
    for n in range(1, 141):
        pid = pub.PatchTable.patch_id(n)
        vals = []
        for c, has in keys:
            m = measured.get(c, {}).get(pid)
            vals.append(_round(m))
            if has:
                p = published[c].get(pid)
                vals += [p, None if m is None or p is None else _round(m - p)]
        rows.append((f"{n} ({pid})", vals, "patch", pid, None, digits))
    # Per column: how the measured and published patches differ overall.
    summary = []
    for stat, key, fn in (("mean difference", "mean-difference", np.mean),
                          ("mean |difference|", "mean-abs-difference", lambda d: np.mean(np.abs(d))),
                          ("largest |difference|", "largest-abs-difference", lambda d: np.max(np.abs(d)))):
        vals = []
        for c, has in keys:
            vals.append(None)
            if has:
                d = [measured.get(c, {}).get(pid) - p for pid, p in published[c].items()
                     if measured.get(c, {}).get(pid) is not None]
                vals += [None, _round(fn(np.array(d))) if d else None]
        summary.append((stat, vals, "summary", key, None, digits))
    body = table(f"{run.short}-{ptable.number.lower().replace(' ', '')}",
                 f"{ptable.number} — {ptable.title} ({ptable.ref()})", heads, summary + rows, corner="patch (SG id)",
                 note=note)
    return (f'<details class="appendix" data-table="{esc(ptable.number)}"><summary>{esc(ptable.number)}: '
            f'{esc(ptable.title)}, each of the 140 patches beside the published value</summary>{body}</details>')


def _by_id(entry) -> dict:
    return {i: float(v) for i, v in zip(entry["ids"], entry["de"])}


def section(run) -> str:
    a = characterization.analyse(run)
    out = ['<h3>Appendix E: every patch (Tables 16-20)</h3><p class="note">Patches numbered as the dissertation '
           'numbers them, left to right from the chart\'s upper left corner (1 = A1, 14 = N1, 15 = A2, 140 = N10); '
           'the differences are measured − published. Open a table to see it.</p>']
    cases = [c for c in ("tiff8", "jpeg", "tiff16") if c in a["space"]]
    if cases:
        out.append(patch_table(run, pub.TABLE16, {c: _by_id(a["space"][c]) for c in cases}, cases, CASE_LABEL,
                               "Measured: ΔE*ab of the camera's colour space (Adobe RGB to L*a*b*) against the reference, "
                               "per test case, as Table 9."))
    icc = [c for c in ("tiff8", "jpeg", "tiff16") if c in a["icc"]]
    if icc:
        out.append(patch_table(run, pub.TABLE17, {c: _by_id(a["icc"][c]) for c in icc}, icc, CASE_LABEL,
                               "Measured: ΔE*ab of the lab's matrix/shaper profile, per test case, as Table 10."))
    if a["poly"]:
        polys = {str(n): _by_id(v) for n, v in a["poly"].items()}
        label = {str(n): f"poly {n}" for n in range(1, 12)}
        fmt = esc(a["poly_format"])
        out.append(patch_table(run, pub.TABLE18, polys, ["1", "2", "3", "4", "5"], label,
                               f"Measured: ΔE*ab of §7.3's polynomials 1-5 fitted on the {fmt} patches, as Table 11. "
                               "The dissertation prints this table's columns as 1-4, but they hold polynomials 2-5 "
                               "(their statistics are Table 11's 2-4 and Table 12's 5; the last equals Table 19's "
                               "first): polynomial 1 has no published per-patch values."))
        out.append(patch_table(run, pub.TABLE19, polys, [str(n) for n in range(5, 12)], label,
                               f"Measured: ΔE*ab of §7.3's polynomials 5-11 fitted on the {fmt} patches, as Table 12."))
    bb = (((run.result.get("formats") or {}).get("raw") or {}).get("approaches") or {}).get("black_box") or {}
    per = ((bb.get("residuals") or {}).get("patches") or {}).get("training")
    if per:
        measured = {ch: {i: float(v) for i, v in zip(per["ids"], per[ch])} for ch in "RGB"}
        out.append(patch_table(run, pub.TABLE20, measured, ["R", "G", "B"], {c: c for c in "RGB"},
                               "Stored: each patch's signed black-box residual, predicted − measured raw counts "
                               "(training), as the run's lab.analysis.characterize stored it; the dissertation does not "
                               "say which way its signs go, so compare magnitudes where signs disagree."))
    elif bb:
        out.append('<p class="note">Table 20: this run predates the stored per-patch residuals.</p>')
    return "\n".join(out) if len(out) > 1 else ""
