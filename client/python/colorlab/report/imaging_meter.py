"""floor-luminance runs: the camera as an imaging luminance meter (issue 11), against the 80-spot LS-110 grid.

The run stores, per lamp and dimmer level, the camera's luminance at every grid spot (F/<lamp>/D<level>/r<r>c<c>),
the LS-110's calibration readings (C/…) and one photograph row (P/<lamp>/D<level>) whose data holds the cheaper
settings the campaign fitted in C++ — the first k calibration spots, the first n frames — with each one's luminance
at every grid spot, and the lab's clock around the photograph (capture_s) and around each calibration spot (spot_s,
the aim and the reading). Nothing is refitted here: the report compares what the lab computed with a stored
cabinet-grid run under the same lamp and level (the run named by the campaign's grid_run parameter, else the
report's newest cabinet-grid run), spot by spot, ΔL/L = (camera − grid) / grid.

Time: the camera's, per lamp and level, is the stored capture time scaled to n frames (capture_s · n / N) plus the
first k calibration spots' stored times; the grid's is the cabinet-grid run's wall time from its start to its last
reading over its lamp × level grids, and per reading that over its readings, × 80 for the full grid. Both are this
lab's wall seconds (the simulated lab's are time-scaled: its instruments wait 1/time-scale of a bench's time, the
camera's rendering does not).

Rule: every spot within 2 % of the LS-110 grid — Konica Minolta's stated accuracy for the LS-100/LS-110 (±2 % ±1
digit, for illuminant A). Neither the dissertation nor instrument-protocols.md quotes it (they give no accuracy at
all), so it is stated here as the manufacturer's figure: closer than that, the grid itself cannot say which is right.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from . import tradeoff as tr
from .html import esc, figure, table
from .plots import subplots, to_svg

RULE_PCT = 2.0        # max |ΔL/L| over every spot, lamp and level (the LS-110's stated accuracy)
FULL_GRID = 80        # §6.2's spots


def _seconds(ts) -> float:
    return pd.Timestamp(ts).timestamp()


def link(client, runs) -> None:
    """Each floor-luminance run's grid: its grid_run when stored (from the report's runs, else fetched), else the
    report's newest cabinet-grid run."""
    from . import fetch
    grids = [r for r in runs if fetch.kind_of(r) == "cabinet-grid"]
    for run in runs:
        if run.campaign != "floor-luminance":
            continue
        ref = (run.doc.get("params") or {}).get("grid_run")
        found = next((g for g in grids if g.id == ref), None) if ref else None
        if ref and found is None:
            try:
                found = fetch.load(client, ref)
            except Exception:  # noqa: BLE001 — the section says it has no grid to compare with
                found = None
        if found is None and not ref and grids:
            found = max(grids, key=lambda g: str(g.doc.get("started_at") or ""))
        run.extra["grid"] = found


def grid_values(grid) -> dict:
    """{(lamp, level): {(row, col): cd/m²}} of a cabinet-grid run's stored readings."""
    out: dict = {}
    for _, m in grid.steps("L/").iterrows():
        out.setdefault((m["data.lamp"], float(m["data.dimmer_percent"])), {})[(int(m["data.row"]), int(m["data.col"]))] = float(m.value)
    return out


def grid_time(grid) -> dict | None:
    """The cabinet-grid run's time: per lamp × level grid and per reading (wall seconds)."""
    rows = grid.steps("L/")
    if rows.empty or not grid.doc.get("started_at") or rows.measured_at.isna().any():
        return None
    span = _seconds(rows.measured_at.max()) - _seconds(grid.doc["started_at"])
    readings = sum(len(r) if isinstance(r, (list, np.ndarray)) else 1 for r in rows.get("data.readings", [1] * len(rows)))
    grids = rows.groupby(["data.lamp", "data.dimmer_percent"]).ngroups
    return {"span": span, "per_grid": span / grids, "per_reading": span / readings, "readings": readings,
            "grids": grids, "spots": len(rows) // grids, "full_grid": FULL_GRID * span / readings}


def agreement(camera: dict, grid: dict) -> dict | None:
    """ΔL/L in % at the spots both have: mean, max |·|, RMS."""
    both = sorted(set(camera) & set(grid))
    if not both:
        return None
    d = np.array([100 * (camera[s] - grid[s]) / grid[s] for s in both])
    return {"n": len(both), "mean": float(d.mean()), "max": float(np.abs(d).max()), "rms": float(np.sqrt((d ** 2).mean())),
            "spots": both, "delta": d}


def photographs(run) -> list[dict]:
    """Per lamp and level: the stored photograph row's data and the camera's luminance at each grid spot."""
    out = []
    for _, p in run.steps("P/").iterrows():
        lamp, level = p["data.lamp"], float(p["data.dimmer_percent"])
        f = run.steps(f"F/{lamp}/D{level:g}/")
        camera = {(int(m["data.row"]), int(m["data.col"])): float(m.value) for _, m in f.iterrows()}
        out.append({"lamp": lamp, "level": level, "camera": camera, "frames": int(p["data.frames"]),
                    "capture_s": float(p["data.capture_s"]), "spot_s": [float(x) for x in p["data.spot_s"]],
                    "variants": p["data.variants"], "rows": int(p["data.grid_rows"]), "cols": int(p["data.grid_cols"]),
                    "degree": int(p["data.degree"])})
    return out


def data(run):
    """Everything the section shows, no HTML: per lamp/level agreement and time, and the Pareto front of settings."""
    grid = run.extra.get("grid")
    photos = photographs(run)
    if not photos or grid is None:
        return {"photos": photos, "grid": grid}
    gv, gt = grid_values(grid), grid_time(grid)
    levels = []
    for ph in photos:
        g = gv.get((ph["lamp"], ph["level"]))
        a = agreement(ph["camera"], g) if g else None
        camera_s = ph["capture_s"] + sum(ph["spot_s"])
        levels.append({**ph, "agreement": a, "camera_s": camera_s})
    compared = [lv for lv in levels if lv["agreement"]]
    # Every setting the campaign fitted, over the lamp/levels with a grid: worst spot and RMS, mean time per level.
    settings = {}
    for lv in compared:
        g = gv[(lv["lamp"], lv["level"])]
        for v in lv["variants"]:
            key = (int(v["spots"]), int(v["frames"]))
            cam = {}
            for i, value in enumerate(v["luminance"]):
                cam[(i // lv["cols"], i % lv["cols"])] = float(value)
            a = agreement(cam, g)
            t = lv["capture_s"] * key[1] / lv["frames"] + sum(lv["spot_s"][:key[0]])
            s = settings.setdefault(key, {"deltas": [], "times": [], "degree": int(v["degree"])})
            s["deltas"].append(a["delta"])
            s["times"].append(t)
    keys = sorted(settings)
    pts = []
    for k in keys:
        d = np.concatenate(settings[k]["deltas"])
        pts.append({"spots": k[0], "frames": k[1], "degree": settings[k]["degree"], "time": float(np.mean(settings[k]["times"])),
                    "max": float(np.abs(d).max()), "rms": float(np.sqrt((d ** 2).mean())), "mean": float(d.mean())})
    costs, errors = [p["time"] for p in pts], [p["max"] for p in pts]
    front = tr.pareto_front(costs, errors) if pts else []
    chosen = tr.cheapest_meeting(costs, errors, RULE_PCT) if pts else None
    return {"photos": photos, "grid": grid, "levels": levels, "grid_time": gt, "points": pts, "front": front,
            "chosen": chosen}


def section(run) -> str:
    d = data(run)
    if not d["photos"]:
        return '<p class="warn">This run stored no floor photographs (P/…): nothing to compare.</p>'
    if d["grid"] is None:
        return ('<p class="warn">No cabinet-grid run to compare with: give the campaign grid_run, or report a '
                'cabinet-grid run beside it.</p>')
    grid, gt = d["grid"], d["grid_time"]
    out = [f'<h3 id="{run.short}-agreement">The camera against the LS-110 grid (cabinet-grid {esc(grid.id)})</h3>']
    cols = ["spots compared", "mean ΔL/L (%)", "max |ΔL/L| (%)", "RMS ΔL/L (%)", "flat-field degree", "camera time (s)",
            "grid time (s)", "grid time, 80 spots (s)"]
    rows = []
    for lv in d["levels"]:
        a = lv["agreement"]
        label = f"{lv['lamp']} {lv['level']:g} %"
        key = f"{lv['lamp']}-{lv['level']:g}"
        if not a:
            rows.append((label + " (no grid)", [None] * len(cols), "measured", key))
            continue
        rows.append((label, [float(a["n"]), a["mean"], a["max"], a["rms"], float(lv["degree"]), lv["camera_s"],
                             gt["per_grid"] if gt else None, gt["full_grid"] if gt else None], "measured", key, None, 3))
    note = (f"ΔL/L = (camera − LS-110 grid) / grid at each grid spot both runs measured, the camera's luminance being the "
            f"campaign's (its flat field fitted on all its calibration spots, all its frames). Camera time: the stored "
            f"photograph's capture time and its calibration spots' times (aim and reading), per lamp and level. Grid time: "
            + (f"cabinet-grid's {gt['span']:.2f} s from its start to its last reading over its {gt['grids']} lamp × level "
               f"grids of {gt['spots']} spots; for 80 spots, its time per reading ({gt['per_reading'] * 1e3:.1f} ms over "
               f"{gt['readings']} readings, warm-ups and settling spread in) × 80. " if gt else "not stored. ")
            + "Wall seconds of this lab (a simulated lab's are time-scaled).")
    out.append(table(f"{run.short}-imaging-agreement", "The camera's floor luminance against the LS-110 grid, per lamp "
                     "and dimmer level", cols, rows, corner="lamp, level", note=note))
    pts, front, k = d["points"], d["front"], d["chosen"]
    if pts:
        rows = [(f"{p['spots']} spot(s), {p['frames']} frame(s)", [float(p["spots"]), float(p["frames"]), float(p["degree"]),
                 p["time"], p["max"], p["rms"], p["mean"], 1.0 if i in front else 0.0], "derived", f"k{p['spots']}n{p['frames']}",
                 None, 3) for i, p in enumerate(pts)]
        name = f"{pts[k]['spots']} calibration spot(s), {pts[k]['frames']} frame(s)" if k is not None else "none"
        note = (f"Each setting is one the campaign fitted (lab.analysis.floor_luminance in C++): its first k calibration "
                f"spots (flat-field degree up to k − 1) and the average of its first n frames. Error: the worst |ΔL/L| "
                f"over every spot, lamp and level compared (also RMS and mean); time: mean over the lamps and levels of "
                f"capture_s · n / N + the first k spots' times. Rule: every spot within {RULE_PCT:g} % of the LS-110 grid "
                f"(the LS-110's stated accuracy, ±2 % ±1 digit, Konica Minolta's figure: neither the dissertation nor "
                f"instrument-protocols.md gives one). <b data-chosen=\"{esc(name if k is not None else '')}\">Cheapest "
                f"setting meeting it: {esc(name)}</b>"
                + (f", {pts[k]['time']:.3f} s per lamp and level against the grid's "
                   f"{gt['per_grid']:.3f} s ({gt['full_grid']:.3f} s for 80 spots)" if k is not None and gt else "") + ".")
        out.append(table(f"{run.short}-pareto-imaging", "The camera as a luminance meter: calibration spots and frames "
                         "against agreement and time (Pareto)", ["spots", "frames", "degree", "time (s)", "max |ΔL/L| (%)",
                                                                  "RMS (%)", "mean (%)", "Pareto front"], rows,
                         corner="setting", note=note))
        fig, (ax1, ax2) = subplots(2, ncols=2, width=9, height=3.4)
        labels = [f"k={p['spots']} n={p['frames']}" if i in front else "" for i, p in enumerate(pts)]
        from .pareto import _front_plot
        _front_plot(ax1, [p["time"] for p in pts], [p["max"] for p in pts], labels, front, k,
                    xlabel="time per lamp and level (s)", ylabel="worst |ΔL/L| (%)", limit=RULE_PCT)
        ax1.set_yscale("log")
        if gt:
            ax1.axvline(gt["per_grid"], color="tab:green", ls="--", lw=1, label="LS-110 grid")
            ax1.legend(fontsize=6)
        ax1.set_title("(a) settings against the grid", fontsize=8)
        best = d["levels"][0]
        for lv in d["levels"]:
            a = lv["agreement"]
            if a:
                ax2.plot(range(a["n"]), a["delta"], ".", ms=4, label=f"{lv['lamp']} {lv['level']:g} %")
        ax2.axhline(RULE_PCT, color="tab:red", ls=":", lw=1)
        ax2.axhline(-RULE_PCT, color="tab:red", ls=":", lw=1)
        ax2.set_xlabel(f"grid spot (row-major, {best['rows']} × {best['cols']})")
        ax2.set_ylabel("ΔL/L (%)")
        ax2.legend(fontsize=6, ncol=2)
        ax2.set_title("(b) the campaign's setting, spot by spot", fontsize=8)
        out.append(figure(f"{run.short}-fig-pareto-imaging", to_svg(fig, f"{run.short}-fig-pareto-imaging"),
                          "The camera as an imaging luminance meter: (a) the worst spot's |ΔL/L| against the time per "
                          "lamp and level for each number of calibration spots and frames averaged, the Pareto front "
                          "(blue), the cheapest setting within the rule (red circle), the LS-110 grid's time (green); "
                          "(b) ΔL/L at every grid spot for the campaign's own setting.", "pareto-imaging"))
    return "\n".join(out)
