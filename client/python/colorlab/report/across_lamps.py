"""Stability across a lamp change (issue 26, docs/ACCURACY.md §6): the characterizations a characterize-camera run
built for other lamps from its raw photograph, through the camera's estimated sensitivities.

The numbers are the analysis library's own (``characterize_across_lamps``, stored by the campaign in the run's result
under formats.<format>.across_lamps.<lamp>): nothing is refitted here. The D65 → TL84 case comes first, as the
cabinet's nightly change; a lamp whose spectrum is its nominal standard rather than a measurement is warned about.

Beside it, the Pareto chart a lab chooses by: photographs taken against ΔE00 reached under another lamp — one
photograph carried across lamps, against one model over two or three photographs. One run cannot measure that (it
holds one photograph), so the points are the accuracy bench's (``bench_analysis_across_lamps --remedy 1 --pareto``),
shipped with the report in data/across_lamps_pareto.json and labelled as such.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from . import tradeoff
from .html import esc, figure, table
from .plots import subplots, to_svg

PARETO_FILE = Path(__file__).with_name("data") / "across_lamps_pareto.json"

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
    out.append(pareto(s))
    return "\n".join(out)


def pareto_points(path: Path = PARETO_FILE) -> dict:
    return json.loads(path.read_text(encoding="utf-8"))


def pareto(s: str, path: Path = PARETO_FILE) -> str:
    """Photographs taken against the average maximum ΔE00 reached, with the front marked."""
    data = pareto_points(path)
    pts = sorted(data["points"], key=lambda p: (p["photographs"], p["max_de00"]))
    cost = [float(p["photographs"]) for p in pts]
    err = [float(p["max_de00"]) for p in pts]
    front = tradeoff.pareto_front(cost, err)
    fig, (ax,) = subplots(1, width=6.0, height=3.4)
    for k, p in enumerate(pts):
        ax.plot(cost[k], err[k], "o" if k in front else "x", color="C0" if k in front else "C3")
        ax.plot(cost[k], p["mean_de00"], ".", color="0.5")
        ax.annotate(p["what"], (cost[k], err[k]), textcoords="offset points", xytext=(6, 4), fontsize=7)
    ax.set_xticks([1, 2, 3])
    ax.set_xlim(0.6, 3.9)
    ax.set_xlabel("photographs taken (lamps)")
    ax.set_ylabel("ΔE00 under the other lamp")
    ax.set_title("max (o front, x dominated) and mean (·), averages over cases", fontsize=8)
    fid = f"{s}-fig-across-lamps-pareto"
    cases = max(p["cases"] for p in pts)
    caption = (f"Photographs taken against ΔE00 reached under another lamp ({esc(', '.join(data['test_lamps']))}), "
               f"averages over {cases} camera × lamp cases. Measured by the accuracy bench, not by this run: "
               f"<code>{esc(data['source'])}</code> (docs/ACCURACY.md §6).")
    rows = [(p["what"], [p["photographs"], p["mean_de00"], p["max_de00"], p["worst_max_de00"],
                         1.0 if k in front else 0.0], "bench", f"pareto:{p['what']}") for k, p in enumerate(pts)]
    return "\n".join([figure(fid, to_svg(fig, fid), caption, "across-lamps-pareto"),
                      table(f"{s}-across-lamps-pareto", "The chart's points (accuracy bench)",
                            ["photographs", "mean ΔE00", "max ΔE00", "worst max ΔE00", "Pareto front"], rows,
                            corner="training")])
