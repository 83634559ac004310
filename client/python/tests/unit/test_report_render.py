"""colorlab.report without a daemon: runs built in memory render to one self-contained, printable document —
no script, no external resource — with each kind's tables and figures, and the kind told by the steps stored
when a lab renamed its copy of a campaign."""
from __future__ import annotations

import contextlib
import io
import re
import unittest

import numpy as np
import pandas as pd

from colorlab.report import render
from colorlab.report.colour import POLYNOMIALS, design, fit_polynomial, stats
from colorlab.report.fetch import RunData, kind_of


def run(campaign, rows, result=None, run_id="01a20a70-bc32-7d8d-bc85-7952b36f7605"):
    m = pd.DataFrame(rows)
    for col, default in (("instrument_id", "dslr"), ("simulated", True), ("unit", "DN")):
        if col not in m:
            m[col] = default
    doc = {"id": run_id, "campaign": campaign, "status": "finished_ok", "params": {}, "simulated": True,
           "instruments": [{"id": "dslr", "model": "Sim 20D", "simulated": True},
                           {"id": "ls110", "model": "LS-110", "simulated": False}],
           "summary": {"script": result or {}}}
    return RunData(doc, m)


def noise_run(campaign="frame-average"):
    rows = [{"step": f"noise/N{n}/{ch}", "quantity": "pixel_stdev", "value": 2.0 / np.sqrt(n) + 0.1}
            for n in (1, 2, 4, 8, 16, 25) for ch in "RGB"]
    return run(campaign, rows)


class Render(unittest.TestCase):
    def test_self_contained_and_printable(self):
        html = render([noise_run()])
        self.assertNotIn("<script", html.lower())
        # Only SVG namespaces may name a URL; nothing is fetched (a data: URL is inline: the empty icon).
        urls = set(re.findall(r"(?:src|href)\s*=\s*[\"']([^\"']+)", html))
        self.assertEqual({u for u in urls if not u.startswith("#") and not u.startswith("data:")}, set())
        self.assertNotIn("@import", html)
        self.assertIn("@media print", html)
        self.assertEqual(html.count("<svg"), 1)
        self.assertIn('id="r7952b36f7605-fig34"', html)
        self.assertIn('id="r7952b36f7605-table2"', html)

    def test_cells_carry_full_precision(self):
        html = render([noise_run()])
        v = 2.0 / np.sqrt(8) + 0.1
        self.assertIn(f'data-row="G-measured" data-col="8" data-kind="measured" data-value="{v!r}"', html)
        self.assertIn('data-row="G-published-median" data-col="8" data-kind="published" data-value="0.59"', html)

    def test_simulated_instruments_named(self):
        html = render([noise_run()])
        self.assertIn('data-instrument="dslr" data-simulated="true"', html)
        self.assertIn('data-instrument="ls110" data-simulated="false"', html)

    def test_kind_by_steps_when_renamed(self):
        self.assertEqual(kind_of(noise_run("my-noise")), "frame-average")
        self.assertEqual(kind_of(run("x", [{"step": "L/D65/D100/r0c0", "quantity": "luminance", "value": 1.0}])),
                         "cabinet-grid")
        self.assertEqual(kind_of(run("x", [{"step": "reading/0", "quantity": "luminance", "value": 1.0}])),
                         "luminance-spot")
        self.assertEqual(kind_of(run("x", [{"step": "what", "quantity": "q", "value": 1.0}])), "other")

    def test_a_broken_run_costs_only_its_own_section(self):
        bad = run("frame-average", [{"step": "noise/Nx/R", "quantity": "pixel_stdev", "value": 1.0}],
                  run_id="01a20a70-0000-7d8d-bc85-000000000001")
        with contextlib.redirect_stderr(io.StringIO()) as err:
            html = render([bad, noise_run()])
        self.assertIn("section failed", err.getvalue())
        self.assertEqual(html.count('data-error="true"'), 1)
        self.assertIn('id="r7952b36f7605-table2"', html)

    def test_other_runs_get_a_summary(self):
        html = render([run("luminance-spot", [{"step": f"reading/{i}", "quantity": "luminance", "value": float(i),
                                               "unit": "cd/m2"} for i in range(5)])])
        self.assertIn('data-row="luminance" data-col="mean" data-kind="measured" data-value="2.0"', html)
        self.assertIn('data-row="luminance" data-col="stdev" data-kind="measured" data-value="%r"'
                      % float(np.std(range(5), ddof=1)), html)


class Polynomials(unittest.TestCase):
    def test_term_counts_as_printed(self):
        # §7.3's list: 3, 5, 6, 8, 9, 11, 13, 20, 16, 29, 19 terms.
        self.assertEqual([len(POLYNOMIALS[n].split()) for n in range(1, 12)], [3, 5, 6, 8, 9, 11, 13, 20, 16, 29, 19])

    def test_design_columns(self):
        x = np.array([[0.5, 0.25, 2.0]])
        self.assertEqual(design(x, 2).tolist(), [[0.5, 0.25, 2.0, 0.25, 1.0]])

    def test_exact_model_recovered(self):
        rng = np.random.default_rng(1)
        rgb = rng.uniform(0, 1, (140, 3))
        lab = design(rgb, 4) @ rng.normal(size=(8, 3))
        np.testing.assert_allclose(fit_polynomial(rgb, lab, 4), lab, atol=1e-9)

    def test_stats(self):
        s = stats([1.0, 2.0, 3.0, 10.0])
        self.assertEqual((s["Min"], s["Max"], s["Median"], s["Mean"]), (1.0, 10.0, 2.5, 4.0))
        self.assertAlmostEqual(s["Stdev"], np.std([1, 2, 3, 10], ddof=1))


if __name__ == "__main__":
    unittest.main()
