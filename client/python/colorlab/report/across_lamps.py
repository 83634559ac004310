"""Stability across a lamp change (issue 26, docs/ACCURACY.md §6): the characterizations a characterize-camera run
built for other lamps from its raw photograph, through the camera's estimated sensitivities.

The numbers are the analysis library's own (``characterize_across_lamps``, stored by the campaign in the run's result
under formats.<format>.across_lamps.<lamp>): nothing is refitted here. The D65 → TL84 case comes first, as the
cabinet's nightly change; a lamp whose spectrum is its nominal standard rather than a measurement is warned about.
"""
from __future__ import annotations

import numpy as np

from .html import esc, table

FIRST = "TL84"  # the cabinet's other lamp the report leads with (issue 26: "the D65 → TL84 case")
COLUMNS = ["effective parameters", "LOO mean ΔE00", "LOO max ΔE00", "LOO p95 ΔE00", "95 % band median ΔE00",
           "95 % band max ΔE00"]


def stored(run) -> list[tuple[str, str, dict]]:
    """(format, lamp, the stored characterization) for every lamp the run characterized across, TL84 first."""
    out = []
    for fmt, f in sorted((run.result.get("formats") or {}).items()):
        for lamp, x in sorted(((f or {}).get("across_lamps") or {}).items()):
            if isinstance(x, dict):
                out.append((fmt, lamp, x))
    return sorted(out, key=lambda t: (t[1] != FIRST, t[0], t[1]))


def figures(x: dict) -> list[float | None]:
    """One row of the table, in COLUMNS' order, from the stored characterization."""
    cv = x.get("cv") or {}
    band = np.asarray((x.get("uncertainty95") or {}).get("de00") or [], dtype=float)
    return [x.get("parameters"), cv.get("mean"), cv.get("max"), cv.get("p95"),
            float(np.median(band)) if band.size else None, float(band.max()) if band.size else None]


def section(run) -> str:
    rows = stored(run)
    if not rows:
        return ""
    s = run.short
    photographed = (run.doc.get("params") or {}).get("lamp") or "?"
    lamps = ", ".join(sorted({lamp for _, lamp, _ in rows}))
    out = [f'<h3 id="{s}-across-lamps">Stability across a lamp change: {esc(photographed)} → {esc(lamps)}</h3>',
           f'<p class="note">The raw photograph under {esc(photographed)} gives the camera\'s spectral sensitivities '
           "(the black box, with its posterior); the chart is predicted under each other lamp from them and the lamp's "
           "spectrum, and every model family is selected on that predicted chart by leave-one-out. LOO figures are on "
           "the predicted chart; the 95 % band is each patch's radius from 40 curve sets drawn from the posterior, "
           "combined with the family's own LOO misfit (docs/ACCURACY.md §6). Inputs under the other lamp: camera RAW "
           "÷ the RAW of a perfect white under it.</p>"]
    body = []
    for fmt, lamp, x in rows:
        label = f"{photographed} → {lamp} ({fmt}): {x.get('family', '?')} {x.get('target', '')}"
        body.append((label, figures(x), "measured" if x.get("lamp_measured") else "nominal", f"{fmt}:{lamp}"))
    out.append(table(f"{s}-across-lamps-table", "Characterizations across lamps, one per lamp, named by it", COLUMNS,
                     body, corner="lamp change (format): chosen family, target"))
    for fmt, lamp, x in rows:
        if x.get("lamp_measured"):
            out.append(f'<p class="note" data-lamp="{esc(lamp)}" data-lamp-measured="true">{esc(lamp)}: the lamp\'s '
                       "measured spectrum was used.</p>")
            continue
        text = "; ".join(x.get("warnings") or []) or (f"lamp {lamp}: its spectrum is a nominal standard, not a "
                                                     "measurement of this lamp")
        out.append(f'<p class="warn" data-lamp="{esc(lamp)}" data-lamp-measured="false">Warning ({esc(fmt)}): '
                   f"{esc(text)}</p>")
    return "\n".join(out)
