"""The report: one section per run, by the run's kind, in one self-contained HTML document."""
from __future__ import annotations

import datetime as dt
import sys

from . import appendix, cabinet_grid, characterization, common, exposure, fetch, frame_average, imaging_meter, pareto, stability, summaries
from . import verification
from . import across_lamps  # issue 26
from .html import document, esc

TITLES = {
    "frame-average": "Noise against frames averaged (§6.1.3)",
    "cabinet-grid": "Light-cabinet uniformity (§6.2)",
    "characterize-camera": "Camera characterization (chapter 7)",
    "chart-read": "Chart reference values (§6.3)",
    "luminance-spot": "Spot luminance",
    "floor-luminance": "The camera as an imaging luminance meter (§6.2's floor)",
    "dimmer-exposure": "Which dimmer setting to use: exposure against dimmer level (§6.2, Tables 7, 8)",
    "verify": "A rendering verified against the measured scene (issue 23)",
    "other": "Run summary",
}


SECTIONS = {"dimmer-exposure": exposure.section, "frame-average": frame_average.section, "cabinet-grid": cabinet_grid.section,
            "characterize-camera": characterization.section, "floor-luminance": imaging_meter.section}
SECTIONS["verify"] = verification.section


def section_for(run) -> str:
    kind = fetch.kind_of(run)
    make = SECTIONS.get(kind)
    ok = True
    try:
        body = make(run) if make else summaries.section(run, kind)
    except Exception as e:  # one odd run (aborted, hand-edited script) must not cost the other runs their sections
        print(f"colorlab report: run {run.id}: the {kind} section failed: {type(e).__name__}: {e}", file=sys.stderr)
        ok = False
        body = (f'<p class="warn" data-error="true">This section could not be made from the stored data '
                f'({esc(type(e).__name__)}: {esc(e)}); the run\'s summary instead:</p>' + summaries.section(run, "other"))
    return (f'<section id="{run.short}" class="run" data-run="{esc(run.id)}" data-kind="{esc(kind)}">'
            f'<h2>{esc(TITLES[kind])} — {esc(run.campaign)} {esc(run.id)}</h2>'
            + common.header(run) + body + (extras(run, kind) if ok else "") + "</section>")


# Speed against accuracy and stability (issue 11): after the campaign's own section, each on its own.
EXTRAS = {"frame-average": (pareto.frames_section,), "cabinet-grid": (pareto.luminance_section,),
          "luminance-spot": (pareto.luminance_section,),
          "characterize-camera": (pareto.characterization_section, stability.section, across_lamps.section,
                                  appendix.section)}


def extras(run, kind) -> str:
    out = []
    for make in EXTRAS.get(kind, ()):
        try:
            out.append(make(run))
        except Exception as e:  # noqa: BLE001 — an extra must not cost the run its section
            print(f"colorlab report: run {run.id}: {make.__module__}.{make.__name__} failed: {type(e).__name__}: {e}",
                  file=sys.stderr)
            out.append(f'<p class="warn" data-error="true">{esc(make.__module__)} could not be made from the stored '
                       f'data ({esc(type(e).__name__)}: {esc(e)}).</p>')
    return "\n".join(out)


def render(runs) -> str:
    now = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    sections = [section_for(r) for r in runs]
    if sections:
        sections[0] = sections[0].replace("<h2>", '<h2 class="first">', 1)
    intro = (f"<h1>colorlab report</h1><p class=\"note\">Generated {esc(now)} from {len(runs)} stored run(s). "
             "Each table stands beside the numbers Ulbricht (2006) published, with the difference; each published "
             "number names its table or figure and its place in the dissertation. Cells shown as — have no "
             "published counterpart (or are illegible in the dissertation's text).</p>")
    return document("colorlab report", intro + "\n".join(sections))


def load_runs(client, run_ids):
    runs = [fetch.load(client, r) for r in run_ids]
    for run in runs:
        ref = (run.doc.get("params") or {}).get("reference_run")
        if fetch.kind_of(run) == "characterize-camera" and ref:
            try:
                run.extra["reference"] = fetch.load(client, ref)
            except Exception:  # the reference only adds the L*a*b* comparisons; the section says when it lacks it
                run.extra["reference"] = None
    imaging_meter.link(client, runs)  # each floor-luminance run's cabinet-grid
    verification.link(client, runs)  # each verify run's chart-read (chapter 8)
    # The stability section's "another lamp": the report's other characterize-camera runs of the same reference.
    cc = [r for r in runs if fetch.kind_of(r) == "characterize-camera"]
    for run in cc:
        p = run.doc.get("params") or {}
        run.extra["other_lamps"] = [o for o in cc if o is not run and (o.doc.get("params") or {}).get("reference_run")
                                    == p.get("reference_run") and (o.doc.get("params") or {}).get("lamp") != p.get("lamp")]
    return runs
