"""The verification section from a verification stored by the daemon (POST /v1/verifications, docs/verify.md
"Report"): a chart-read on the simulated lab, a verification against it posted as `colorlab verify --store` posts
one (one patch 3 ΔE00 off, one spot 8 % bright), the report made through `python3 -m colorlab.report` with the
verify run alone — so the chart-read for chapter 8 is found through the verification's `against`. Every number in
the per-patch and per-spot tables is the one stored in SQLite, the defects and only they show "differs", the
summary's counts are the daemon's, the rendering's hostile name is text, and Chromium shows the figures."""
from __future__ import annotations

import re
import unittest

import numpy as np

from report_support import ReportCase, check_in_browser, make_report, parse

HOSTILE = 'box<img src=x onerror="window.__pwned=1">.exr'


def short(run_id):
    return "r" + run_id.replace("-", "")[-12:]


def comparison(kind, where, rendered, measured, difference, expanded, differs):
    threshold = 2.8328 if kind == "colour_7_3" else 2.0
    distance = threshold * abs(difference) / expanded
    return {"kind": kind, "where": where, "rendered": rendered, "measured": measured, "difference": difference,
            "expanded": expanded, "mahalanobis": distance, "threshold": threshold,
            "verdict": "differs" if differs else "agrees", "cannot_tell": False,
            "budget": {"characterization": 0.4, "frame noise": 0.1} if kind == "colour_7_3"
            else {"ls110 repeatability": 0.003, "lamp drift": 0.0058}}


class VerificationReport(ReportCase):
    SEED = 9

    @classmethod
    def campaigns(cls, d):
        cls.chart = d.run_to_end("chart-read")["run_id"]
        ids = [m["data"]["id"] for m in d.stored_measurements(cls.chart) if m["quantity"] == "reflectance_spectrum"]
        cls.defect_patch, cls.defect_spot = ids[29], "r1c2"
        rng = np.random.default_rng(9)
        comps = []
        cls.patches = len(dict.fromkeys(ids))
        for pid in dict.fromkeys(ids):
            lab = [float(x) for x in rng.uniform([20, -40, -40], [90, 40, 40])]
            bad = pid == cls.defect_patch
            comps.append(comparison("colour_7_3", pid, [lab[0] + (3.1 if bad else 0.2), lab[1], lab[2]], lab,
                                    3.1 if bad else float(rng.uniform(0, 0.5)), 1.1, bad))
        for r in range(4):
            for c in range(5):
                where = f"r{r}c{c}"
                m = float(rng.uniform(150, 320))
                bad = where == cls.defect_spot
                d_ = 0.08 if bad else float(rng.uniform(-0.01, 0.01))
                comps.append(comparison("light_spot", where, [m * (1 + d_)], [m], d_, 0.021, bad))
        body = {"rendering": HOSTILE, "against": [cls.chart], "scale": 1.0, "k": 2,
                "result": {"summary": {"scales": [{"kind": "light_spot", "how": "given", "factor": 1.0}]},
                           "comparisons": comps, "floor_difference": []}}
        cls.posted = d.client.conn.post("/v1/verifications", body)
        cls.vid = cls.posted["run_id"]
        cls.path = make_report(d, [cls.vid], "verification")
        cls.html = cls.path.read_text(encoding="utf-8")
        cls.tables, cls.ids = parse(cls.path)

    def test_stored_numbers_in_the_tables(self):
        s = short(self.vid)
        rows = self.daemon.stored_measurements(self.vid)
        self.assertEqual(len(rows), self.patches + 20)
        for m in rows:
            kind = m["step"].split("/", 1)[0]
            table = self.tables[f"{s}-verify-{kind}"]
            scale = 1.0 if kind == "colour_7_3" else 100.0
            self.assertEqual(table[(m["step"], "difference", None)], scale * m["value"], m["step"])
            self.assertEqual(table[(m["step"], "expanded", None)], scale * m["data"]["expanded"], m["step"])
            if kind == "light_spot":
                self.assertEqual(table[(m["step"], "measured", None)], m["data"]["measured"][0])
                self.assertEqual(table[(m["step"], "rendered", None)], m["data"]["rendered"][0])

    def test_defects_and_only_they_differ(self):
        differs = set(re.findall(r'<tr data-row="([^"]+)" data-verdict="differs">', self.html))
        self.assertEqual(differs, {f"colour_7_3/{self.defect_patch}", f"light_spot/{self.defect_spot}"})
        self.assertEqual(self.posted["verdict"], "differs")
        self.assertIn(f'data-verdict="differs" id="{short(self.vid)}-verdict"', self.html)

    def test_summary_is_the_daemons(self):
        stored = self.daemon.client.conn.get(f"/v1/runs/{self.vid}")["summary"]["kinds"]
        table = self.tables[f"{short(self.vid)}-verify-summary"]
        for kind, k in stored.items():
            for col in ("compared", "agree", "differ"):
                self.assertEqual(table[(kind, col, None)], k[col], (kind, col))

    def test_chapter8_from_the_stored_chart_read(self):
        lamps = self.tables[f"{short(self.vid)}-ch8-lamps"]
        self.assertEqual({row for row, _, _ in lamps}, {"D65", "TL84", "CWF", "A"})
        self.assertLess(lamps[("D65", "rgb max", None)], 0.02)  # the RGB renderer's albedos are D65 colours
        self.assertGreater(lamps[("CWF", "rgb max", None)], 3.0)  # and not CWF's: chapter 8's point
        self.assertIn(self.chart, self.html)

    def test_hostile_name_is_text(self):
        self.assertNotIn("<img", self.html.lower())
        self.assertIn("box&lt;img src=x onerror=&quot;window.__pwned=1&quot;&gt;.exr", self.html)

    def test_in_a_browser(self):
        s = short(self.vid)
        check_in_browser(self, self.path, [f"{s}-fig-verify-chart", f"{s}-fig-verify-floor", f"{s}-fig-ch8"],
                         "verification")


if __name__ == "__main__":
    unittest.main()
