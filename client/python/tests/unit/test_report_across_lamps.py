"""The report's stability-across-lamps section (issue 26) without a daemon: a characterize-camera run whose result
holds the analysis library's across-lamps characterizations renders them with the stored numbers, the D65 → TL84
case first, and warns for a lamp given by its nominal standard but not for a measured one."""
from __future__ import annotations

import html
import re
import unittest

import numpy as np
import pandas as pd

from colorlab.report import across_lamps, render
from colorlab.report.fetch import RunData

WARNING = ("lamp TL84: its spectrum is the nominal standard F11, not a measurement of this lamp; a real TL84 differs "
           "from its standard (phosphors, age, dimming)")


def characterization(lamp, measured, family, band, cv):
    return {"lamp": lamp, "lamp_measured": measured, "warnings": [] if measured else [WARNING],
            "method": f"across-lamps:{lamp}:{family}", "family": family, "target": "xyz", "parameters": 13.0,
            "cv": cv, "uncertainty95": {"ids": [f"P{i}" for i in range(len(band))], "de00": band}}


def lamp_run():
    band_tl84 = [1.25, 0.75, 2.5, 1.0, 0.5]
    band_a = [2.0, 3.0, 1.5, 4.5]
    result = {"formats": {"raw": {"across_lamps": {
        "A": characterization("A", True, "rootpoly:3", band_a, {"mean": 0.61, "max": 1.47, "p95": 1.2}),
        "TL84": characterization("TL84", False, "rbf:ccm", band_tl84, {"mean": 0.41, "max": 1.08, "p95": 0.9})}}}}
    m = pd.DataFrame([{"step": "characterization/raw/lamp/TL84", "quantity": "delta_e00_cv_mean", "value": 0.41,
                       "unit": "ΔE00", "instrument_id": "dslr", "simulated": True}])
    doc = {"id": "01a20a70-bc32-7d8d-bc85-7952b36f7605", "campaign": "characterize-camera", "status": "finished_ok",
           "params": {"lamp": "D65"}, "simulated": True, "instruments": [], "summary": {"script": result}}
    return RunData(doc, m), {"TL84": band_tl84, "A": band_a}


def cells(text, row):
    """{column: data-value} of one table row's cells."""
    return {html.unescape(c): float(v) for c, v in
            re.findall(rf'data-row="{re.escape(html.escape(row))}" data-col="([^"]+)" data-kind="[^"]*" data-value="([^"]+)"', text)}


class AcrossLampsSection(unittest.TestCase):
    def test_numbers_are_the_stored_analysis_output(self):
        run, bands = lamp_run()
        text = across_lamps.section(run)
        for lamp, row in (("TL84", "raw:TL84"), ("A", "raw:A")):
            x = run.result["formats"]["raw"]["across_lamps"][lamp]
            got = cells(text, row)
            self.assertEqual(got["LOO mean ΔE00"], x["cv"]["mean"])
            self.assertEqual(got["LOO max ΔE00"], x["cv"]["max"])
            self.assertEqual(got["LOO p95 ΔE00"], x["cv"]["p95"])
            self.assertEqual(got["effective parameters"], x["parameters"])
            self.assertEqual(got["95 % band median ΔE00"], float(np.median(bands[lamp])))
            self.assertEqual(got["95 % band max ΔE00"], max(bands[lamp]))
        # The D65 → TL84 case leads, and the heading names the photographed lamp.
        self.assertLess(text.index('data-row="raw:TL84"'), text.index('data-row="raw:A"'))
        self.assertIn("Stability across a lamp change: D65 →", text)

    def test_nominal_lamp_warned_measured_not(self):
        run, _ = lamp_run()
        text = across_lamps.section(run)
        self.assertRegex(text, r'<p class="warn" data-lamp="TL84" data-lamp-measured="false">[^<]*nominal standard F11')
        self.assertNotRegex(text, r'class="warn" data-lamp="A"')
        self.assertIn('data-lamp="A" data-lamp-measured="true"', text)

    def test_in_the_report_and_absent_without_lamps(self):
        run, _ = lamp_run()
        self.assertIn(f'id="{run.short}-across-lamps-table"', render([run]))
        run.doc["summary"]["script"] = {"formats": {"raw": {"across_lamps": {}}}}
        self.assertEqual(across_lamps.section(run), "")

    def test_pareto_points_are_the_bench_output(self):
        run, _ = lamp_run()
        text = across_lamps.section(run)
        data = across_lamps.pareto_points()
        self.assertIn(f'id="{run.short}-fig-across-lamps-pareto"', text)
        self.assertEqual(sorted(p["photographs"] for p in data["points"]), [1, 1, 2, 3])
        for p in data["points"]:
            got = cells(text, f"pareto:{p['what']}")
            self.assertEqual(got["photographs"], p["photographs"])
            self.assertEqual(got["mean ΔE00"], p["mean_de00"])
            self.assertEqual(got["max ΔE00"], p["max_de00"])
            self.assertEqual(got["worst max ΔE00"], p["worst_max_de00"])
        # The front by its definition: no other point at most as many photographs and at most its max ΔE00, and
        # better in one.
        pts = data["points"]
        for p in pts:
            dominated = any(q is not p and q["photographs"] <= p["photographs"] and q["max_de00"] <= p["max_de00"]
                            and (q["photographs"] < p["photographs"] or q["max_de00"] < p["max_de00"]) for q in pts)
            self.assertEqual(cells(text, f"pareto:{p['what']}")["Pareto front"], 0.0 if dominated else 1.0, p["what"])
        self.assertIn(html.escape(data["source"]), text)


if __name__ == "__main__":
    unittest.main()
