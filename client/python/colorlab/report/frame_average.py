"""frame-average runs: Table 2 and fig. 34 (§6.1.3), noise against the number of frames averaged."""
from __future__ import annotations

import numpy as np

from . import published as pub
from .html import difference, esc, figure, table
from .plots import subplots, to_svg

CHANNELS = ("R", "G", "B")
COLOURS = {"R": "tab:red", "G": "tab:green", "B": "tab:blue"}


def noise_table(run) -> dict:
    """{channel: {frames averaged: stdev}} from the run's noise/N<n>/<channel> measurements."""
    out: dict = {}
    for _, m in run.steps("noise/N").iterrows():
        n = int(m.step.split("/")[1][1:])
        out.setdefault(m.step.split("/")[2], {})[n] = float(m.value)
    return out


def section(run) -> str:
    noise = noise_table(run)
    if not noise:
        return '<p class="warn">This run stored no noise measurements (noise/N…): nothing to tabulate.</p>'
    frames = sorted({n for per in noise.values() for n in per})
    channels = [c for c in CHANNELS if c in noise] + sorted(set(noise) - set(CHANNELS))
    unit = run.steps("noise/N").unit.iloc[0]
    columns = [str(n) for n in frames]

    def published_row(label):
        try:
            row = pub.TABLE2.row(label)
        except StopIteration:
            return [None] * len(frames)
        by_n = dict(zip(pub.TABLE2.columns, row.values()))
        return [by_n.get(str(n)) for n in frames]

    rows, rel_rows = [], []
    for ch in channels:
        measured = [noise[ch].get(n) for n in frames]
        med, mean = published_row(f"{ch} median"), published_row(f"{ch} mean")
        rows += [(f"{ch} measured ({unit})", measured, "measured", f"{ch}-measured"),
                 (f"{ch} published median", med, "published", f"{ch}-published-median"),
                 (f"{ch} measured − published median", difference(measured, med), "difference", f"{ch}-diff-median"),
                 (f"{ch} published mean", mean, "published", f"{ch}-published-mean"),
                 (f"{ch} measured − published mean", difference(measured, mean), "difference", f"{ch}-diff-mean")]
        # Relative to one frame, the two noise levels become comparable whatever the camera's counts.
        one = noise[ch].get(1)
        rel = [None if v is None or not one else v / one for v in measured]
        prel = [None if v is None or med[0] is None or frames[0] != 1 else v / med[0] for v in med]
        rel_rows += [(f"{ch} measured σN/σ1", rel, "measured", f"{ch}-measured", None, 3),
                     (f"{ch} published median σN/σ1", prel, "published", f"{ch}-published-median", None, 3),
                     (f"{ch} difference", difference(rel, prel), "difference", f"{ch}-diff", None, 3),
                     (f"{ch} 1/√N (pure random noise)", [1 / np.sqrt(n) for n in frames], "model", f"{ch}-model", None, 3)]
    region = run.result.get("region") or (run.steps("noise/N").iloc[0].get("data.region") if "data.region" in run.measurements else None)
    out = [table(f"{run.short}-table2", f"Table 2 — noise against frames averaged ({pub.TABLE2.ref()})",
                 columns, rows, corner="frames averaged",
                 note=("Measured: the spatial standard deviation of the averaged region "
                       f"{esc(list(region) if region is not None else '')} per CFA channel, as the campaign stored it. "
                       "Published: the median and mean over the 140 patches of the dissertation's standard deviations "
                       "(its camera, its 8-bit counts). The absolute numbers differ in kind; the fall with N is what "
                       "compares, in the table below.")),
           table(f"{run.short}-table2-relative", "Table 2, relative to one frame (derived from the rows above)",
                 columns, rel_rows, corner="frames averaged"),
           figure(f"{run.short}-fig34", fig34(run, noise, frames, channels),
                  "Fig. 34 — noise against frames averaged: (a) as measured, (b) relative to one frame beside the "
                  "dissertation's medians (dashed) and 1/√N (dotted).", "34")]
    return "\n".join(out)


def fig34(run, noise, frames, channels) -> str:
    fig, (a, b) = subplots(2, width=8, height=3.2)
    for ch in channels:
        ns = sorted(noise[ch])
        a.plot(ns, [noise[ch][n] for n in ns], "o-", color=COLOURS.get(ch), label=ch)
        if 1 in noise[ch] and noise[ch][1]:
            b.plot(ns, [noise[ch][n] / noise[ch][1] for n in ns], "o-", color=COLOURS.get(ch), label=f"{ch} measured")
        med = pub.TABLE2.row(f"{ch} median").values() if ch in CHANNELS else None
        if med:
            b.plot([int(c) for c in pub.TABLE2.columns], [v / med[0] for v in med], "s--", color=COLOURS.get(ch),
                   alpha=0.6, label=f"{ch} published")
    n = np.array(sorted(set(frames) | {1, 25}))
    b.plot(n, 1 / np.sqrt(n), "k:", label="1/√N")
    for ax in (a, b):
        ax.set_xscale("log", base=2)
        ax.set_xticks(frames, [str(f) for f in frames])
        ax.set_xlabel("frames averaged")
    a.set_ylabel("standard deviation (%s)" % run.steps("noise/N").unit.iloc[0])
    a.set_title("(a) measured")
    b.set_ylabel("σN / σ1")
    b.set_title("(b) relative to one frame")
    a.legend(fontsize=7)
    b.legend(fontsize=6, ncol=2)
    return to_svg(fig, f"{run.short}-fig34")
