"""The part of every run's section that is not about its campaign: what ran, when, on which instruments."""
from __future__ import annotations

from .html import esc


def header(run) -> str:
    d = run.doc
    params = ", ".join(f"{k} = {v}" for k, v in sorted((d.get("params") or {}).items()))
    rows = [("Run", d.get("id")), ("Campaign", d.get("campaign")), ("Status", d.get("status")),
            ("Started", d.get("started_at")), ("Finished", d.get("finished_at")), ("Parameters", params or "—"),
            ("Measurements", d.get("measurement_count", len(run.measurements)))]
    body = "".join(f'<tr><th class="label">{esc(k)}</th><td class="label">{esc(v)}</td></tr>' for k, v in rows)
    return f'<table id="{run.short}-run" class="run">{body}</table>' + instruments(run)


def instruments(run) -> str:
    """Which instruments the run used and whether each was simulated — by the run's own instrument record,
    and by the measurements' flag, which the daemon sets and no script can clear."""
    used = set()
    sim_measurements = 0
    m = run.measurements
    if not m.empty:
        used = set(m.instrument_id.dropna())
        sim_measurements = int(m.simulated.sum()) if "simulated" in m else 0
    rows = []
    for inst in run.doc.get("instruments") or []:
        rows.append(f'<tr data-instrument="{esc(inst.get("id"))}" data-simulated="{str(bool(inst.get("simulated"))).lower()}">'
                    f'<td class="label">{esc(inst.get("id"))}</td><td class="label">{esc(inst.get("model"))}</td>'
                    f'<td class="label">{"yes" if inst.get("id") in used else "no"}</td>'
                    f'<td class="label">{"SIMULATED" if inst.get("simulated") else "real"}</td></tr>')
    sim_used = sorted(i.get("id") for i in run.doc.get("instruments") or [] if i.get("simulated") and i.get("id") in used)
    if run.doc.get("simulated") or sim_measurements:
        banner = (f'<p class="simulated" data-simulated="true">Simulated data: {sim_measurements} of {len(m)} '
                  f'measurements come from simulated instruments ({esc(", ".join(sim_used) or "see below")}); '
                  'they are the simulated lab\'s, not the dissertation\'s bench.</p>')
    else:
        banner = '<p class="note" data-simulated="false">All measurements come from real instruments.</p>'
    return (banner + f'<table id="{run.short}-instruments"><caption>Instruments</caption>'
            '<thead><tr><th class="label">id</th><th class="label">model</th><th class="label">measured</th>'
            '<th class="label">real or simulated</th></tr></thead><tbody>' + "".join(rows) + "</tbody></table>")
