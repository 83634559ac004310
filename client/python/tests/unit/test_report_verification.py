"""The report's verification section (docs/verify.md "Report") without a daemon.

The verification is built the way verify/compare/src/stored.cpp stores one (step <kind>/<where>, value = the
difference, data = the comparison with its verdict and budget; the summary as the run's summary) and read through
the client's own flattening (colorlab.tables.measurements_frame), so the section sees what GET …/measurements gives.
Checks: every stored number is in the HTML at full precision, a planted defect patch and spot show "differs" and
nothing else does, hostile strings arrive as text only. Chapter 8's numbers are checked against this test's own
computation from ../shared/data's CIE tables (not colord's, which the report reads) with IEC 61966-2-1's printed
sRGB matrix, and the locus test against matplotlib's point-in-path.
"""
from __future__ import annotations

import os
import re
import unittest
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd

from colorlab.report import render
from colorlab.report.fetch import RunData, kind_of
from colorlab.report.tradeoff import delta_e00
from colorlab.tables import measurements_frame

HOSTILE = '<img src=x onerror="window.__pwned=1">'
RUN_ID = "01a20a70-bc32-7d8d-bc85-0000000000f1"
SHORT = "r0000000000f1"
DEFECT_PATCH, DEFECT_SPOT = "F5", "r2c3"


def shared_data() -> Path | None:
    if os.environ.get("COLORLAB_SHARED_DATA"):
        return Path(os.environ["COLORLAB_SHARED_DATA"])
    starts = [Path(os.environ["COLORLAB_SOURCE_DIR"])] if os.environ.get("COLORLAB_SOURCE_DIR") else []
    for start in starts + [Path.cwd(), Path(__file__).resolve()]:
        for d in [start, *start.parents]:
            for candidate in (d / "shared" / "data", d.parent / "shared" / "data"):
                if candidate.is_dir():
                    return candidate
    return None


def comparison(kind, where, rendered, measured, difference, expanded, differs, budget, cannot_tell=False):
    dim = 3 if kind.startswith("colour") else 1
    threshold = 2.8328 if dim == 3 else 2.0
    return {"kind": kind, "where": where, "rendered": rendered, "measured": measured, "difference": difference,
            "expanded": expanded, "mahalanobis": threshold * difference / expanded, "threshold": threshold,
            "verdict": "differs" if differs else "agrees", "cannot_tell": cannot_tell, "budget": budget}


def stored_verification():
    rng = np.random.default_rng(3)
    comps = []
    for r in range(1, 11):
        for c in "ABCDEFGHIJKLMN":
            pid = f"{c}{r}"
            lab = [float(x) for x in rng.uniform([20, -40, -40], [90, 40, 40])]
            defect = pid == DEFECT_PATCH
            d = 3.0 + rng.uniform(0, 0.3) if defect else float(rng.uniform(0, 0.6))
            comps.append(comparison("colour_7_3", pid, [lab[0] + 1e-3, lab[1], lab[2]], lab, d,
                                    float(rng.uniform(0.9, 1.4)), defect,
                                    {"characterization": 0.4, "frame noise": 0.1, HOSTILE: 0.05},
                                    cannot_tell=pid == "A1"))
    for kind in ("light_spot", "light_floor"):
        for r in range(8):
            for c in range(10):
                where = f"r{r}c{c}"
                defect = kind == "light_spot" and where == DEFECT_SPOT
                measured = float(rng.uniform(150, 320))
                d = 0.08 if defect else float(rng.uniform(-0.01, 0.01))
                comps.append(comparison(kind, where, [measured * (1 + d)], [measured], d, 0.021, defect,
                                        {"ls110 repeatability": 0.003, "lamp drift": 0.0058}))
    comps.append(comparison("light_spot", "</td><script>x</script>", [1.0], [1.0], 0.0, 0.02, False, {}))
    items = [{"seq": i + 1, "step": f"{c['kind']}/{c['where']}", "instrument_id": "verify",
              "quantity": "delta_e00" if c["kind"] == "colour_7_3" else "relative_difference", "value": c["difference"],
              "unit": "ΔE00" if c["kind"] == "colour_7_3" else "1", "measured_at": "2026-11-29T06:00:00Z",
              "simulated": False, "data": c} for i, c in enumerate(comps)]
    kinds = {}
    for kind in ("colour_7_3", "light_spot", "light_floor"):
        ks = [c for c in comps if c["kind"] == kind]
        wrong = [c for c in ks if c["verdict"] == "differs"]
        kinds[kind] = {"compared": len(ks), "agree": len(ks) - len(wrong), "differ": len(wrong),
                       "agree_fraction": 1 - len(wrong) / len(ks),
                       "median_abs_difference": float(np.median([abs(c["difference"]) for c in ks])),
                       "renderer_wrong_at": [{"where": c["where"], "difference": c["difference"],
                                              "expanded": c["expanded"]} for c in wrong],
                       "measurement_cannot_tell_at": [{"where": c["where"], "expanded": c["expanded"],
                                                       "dominant_source": HOSTILE} for c in ks if c["cannot_tell"]],
                       "worst": max(({"where": c["where"], "difference": c["difference"], "expanded": c["expanded"]}
                                     for c in ks), key=lambda w: abs(w["difference"]))}
    summary = {"verdict": "differs", "coverage_k": 2, "kinds": kinds,
               "scales": [{"kind": "light_spot", "how": "given", "factor": 1.0}], "floor_difference": []}
    doc = {"id": RUN_ID, "campaign": "verify", "status": "finished_ok", "simulated": False, "instruments": [],
           "params": {"rendering": f"box{HOSTILE}.exr", "against": ['"><script>alert(1)</script>'], "scale": 1.0,
                      "k": 2},
           "summary": summary}
    return RunData(doc, measurements_frame(items)), comps


def textured_verification(noise_pooling="median-screen", rendering_noise=True):
    """A verification stored today (params with its noise pooling) where the screen left one spot out."""
    comps = [comparison("light_spot", f"r0c{c}", [100.0], [100.0], 0.001, 0.02, False, {"rendering noise": 0.002})
             for c in range(10)]
    comps[4]["noise_left_out"] = True
    comps[4]["budget"]["rendering noise"] = 0.03
    for c in comps:
        c.setdefault("noise_left_out", False)
    items = [{"seq": i + 1, "step": f"light_spot/{c['where']}", "instrument_id": "verify", "quantity": "relative_difference",
              "value": c["difference"], "unit": "1", "measured_at": "2026-11-29T06:00:00Z", "simulated": False, "data": c}
             for i, c in enumerate(comps)]
    summary = {"verdict": "agrees", "coverage_k": 2, "scales": [], "kinds": {"light_spot": {
        "compared": 10, "agree": 10, "differ": 0, "agree_fraction": 1.0, "median_abs_difference": 0.001,
        "renderer_wrong_at": [], "measurement_cannot_tell_at": [], "rendering_noise_left_out": ["r0c4"]}}}
    params = {"rendering": "box.exr", "against": ["g"], "scale": 1.0, "k": 2, "rendering_noise": rendering_noise,
              "noise_neighbours": 8 if rendering_noise else None, "noise_pooling": noise_pooling}
    doc = {"id": "01a20a70-bc32-7d8d-bc85-0000000000f2", "campaign": "verify", "status": "finished_ok",
           "simulated": False, "instruments": [], "params": params, "summary": summary}
    return RunData(doc, measurements_frame(items))


class NoiseScreenInTheReport(unittest.TestCase):
    def test_the_left_out_spot_is_named_and_the_pooling_said(self):
        cells = parse(render([textured_verification()]))
        named = [a["data-noise-left-out"] for t, a in cells.tags if "data-noise-left-out" in a]
        self.assertEqual(named, ["r0c4"])
        pooling = [a["data-noise-pooling"] for t, a in cells.tags if "data-noise-pooling" in a]
        self.assertEqual(pooling, ["median-screen"])
        self.assertIn("its own spread alone", "".join(cells.text))

    def test_from_the_comparisons_when_the_summary_lacks_the_list(self):
        run = textured_verification()
        del run.doc["summary"]["kinds"]["light_spot"]["rendering_noise_left_out"]
        cells = parse(render([run]))
        self.assertEqual([a["data-noise-left-out"] for t, a in cells.tags if "data-noise-left-out" in a], ["r0c4"])

    def test_off_says_off(self):
        run = textured_verification(noise_pooling=None, rendering_noise=False)
        cells = parse(render([run]))
        self.assertEqual([a["data-noise-pooling"] for t, a in cells.tags if "data-noise-pooling" in a], ["off"])


class Cells(HTMLParser):
    """Every <td>'s attributes and text, and every <tr data-row>'s data-verdict."""

    def __init__(self):
        super().__init__()
        self.cells, self.rows, self._td, self._text = [], {}, None, []
        self.tags, self.text = [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        if tag == "tr" and "data-row" in a:
            self.rows[a["data-row"]] = a.get("data-verdict")
        if tag == "td":
            self._td, self._text = a, []

    def handle_data(self, data):
        self.text.append(data)
        if self._td is not None:
            self._text.append(data)

    def handle_endtag(self, tag):
        if tag == "td" and self._td is not None:
            self.cells.append((self._td, "".join(self._text)))
            self._td = None

    def value(self, table_row, col):
        for a, _ in self.cells:
            if a.get("data-row") == table_row and a.get("data-col") == col and "data-value" in a:
                return float(a["data-value"])
        raise KeyError((table_row, col))


def parse(html) -> Cells:
    p = Cells()
    p.feed(html)
    return p


class VerificationSection(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.vrun, cls.comps = stored_verification()
        cls.html = render([cls.vrun])
        cls.cells = parse(cls.html)

    def test_a_row_stored_before_the_pooling_was_recorded_says_so(self):
        # stored_verification()'s params have no noise fields, as a verification stored before them: not recorded,
        # and no region named as left out (nothing stored says so).
        self.assertNotIn("noise_pooling", self.vrun.doc["params"])
        pooling = [a["data-noise-pooling"] for t, a in self.cells.tags if "data-noise-pooling" in a]
        self.assertEqual(pooling, ["not recorded"])
        self.assertIn("pooling: not recorded", "".join(self.cells.text))
        self.assertFalse([a for t, a in self.cells.tags if "data-noise-left-out" in a])

    def test_kind_and_section(self):
        self.assertEqual(kind_of(self.vrun), "verify")
        self.assertIn('data-kind="verify"', self.html)
        self.assertNotIn('data-error="true"', self.html)
        self.assertIn(f'id="{SHORT}-verdict"', self.html)
        self.assertIn(f'id="{SHORT}-fig-verify-chart"', self.html)
        self.assertIn(f'id="{SHORT}-fig-verify-floor"', self.html)

    def test_numbers_are_the_stored_ones(self):
        for c in self.comps:
            key = f"{c['kind']}/{c['where']}"
            if c["kind"] == "colour_7_3":
                self.assertEqual(self.cells.value(key, "difference"), c["difference"], key)
                self.assertEqual(self.cells.value(key, "expanded"), c["expanded"], key)
                self.assertEqual(self.cells.value(key, "mahalanobis"), c["mahalanobis"], key)
            else:
                self.assertEqual(self.cells.value(key, "difference"), 100 * c["difference"], key)
                self.assertEqual(self.cells.value(key, "expanded"), 100 * c["expanded"], key)
                self.assertEqual(self.cells.value(key, "rendered"), c["rendered"][0], key)
                self.assertEqual(self.cells.value(key, "measured"), c["measured"][0], key)
                self.assertEqual(self.cells.value(key, "ratio"), 1 + c["difference"], key)
        for kind, k in self.vrun.doc["summary"]["kinds"].items():
            for col in ("compared", "agree", "differ"):
                self.assertEqual(self.cells.value(kind, col), k[col], (kind, col))

    def test_defects_differ_and_nothing_else(self):
        differs = {row for row, v in self.cells.rows.items() if v == "differs"}
        self.assertEqual(differs, {f"colour_7_3/{DEFECT_PATCH}", f"light_spot/{DEFECT_SPOT}"})
        texts = {a.get("data-verdict"): t for a, t in self.cells.cells if "data-verdict" in a}
        self.assertEqual(texts["differs"], "differs")
        wrong = re.findall(r'data-wrong="([^"]+)"', self.html)
        self.assertEqual(sorted(wrong), sorted([DEFECT_PATCH, DEFECT_SPOT]))
        self.assertIn('data-blind="A1"', self.html)

    def test_hostile_strings_are_text(self):
        low = self.html.lower()
        self.assertNotIn("<script", low)
        self.assertNotIn("<img", low)
        self.assertFalse(any(k.startswith("on") for _, a in self.cells.tags for k in a), "an inline on… attribute")
        texts = [t for _, t in self.cells.cells]
        self.assertIn("</td><script>x</script>", texts)
        self.assertIn(HOSTILE, "".join(self.cells.text))  # the budget source, in the cannot-tell list
        self.assertIn(f"box{HOSTILE}.exr", self.html.replace("&lt;", "<").replace("&gt;", ">").replace("&quot;", '"'))

    def test_chapter8_absent_is_said(self):
        self.assertIn(f'id="{SHORT}-ch8-absent"', self.html)


IEC_XYZ_TO_SRGB = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]])


def lab(xyz, white):
    t = xyz / white
    f = np.where(t > (6 / 29) ** 3, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack([116 * f[:, 1] - 16, 500 * (f[:, 0] - f[:, 1]), 200 * (f[:, 1] - f[:, 2])], axis=1)


class Chapter8(unittest.TestCase):
    """The chart-read's SG spectra (shared data) in a chart-read run; the report's numbers against this test's."""

    @classmethod
    def setUpClass(cls):
        data = shared_data()
        if data is None:
            raise unittest.SkipTest("../shared/data not present")
        sg = pd.read_csv(data / "colorcheckersg_xrite_after_nov2014_dcamprof_10nm_380_730.csv")
        cls.wl = sg.wavelength_nm.to_numpy(float)
        cls.ids = list(sg.columns[1:])
        cls.refl = sg[cls.ids].to_numpy(float).T
        cmf = pd.read_csv(data / "cie1931_2deg_cmf_1nm_360_830.csv").set_index("wavelength_nm")
        cls.cmf = cmf.loc[cls.wl.astype(int)].to_numpy(float)
        cls.cmf_1nm = cmf
        lamps = pd.read_csv(data / "cie_illuminants_A_D50_D65_F2_F11_5nm_380_780.csv").set_index("wavelength_nm")
        cls.lamps = {"D65": lamps.loc[cls.wl.astype(int), "D65"].to_numpy(float),
                     "TL84": lamps.loc[cls.wl.astype(int), "F11"].to_numpy(float),
                     "CWF": lamps.loc[cls.wl.astype(int), "F2"].to_numpy(float),
                     "A": lamps.loc[cls.wl.astype(int), "A"].to_numpy(float)}
        items = [{"seq": i + 1, "step": f"patch/{pid}", "instrument_id": "spectro", "quantity": "reflectance_spectrum",
                  "value": 50.0, "unit": "L*", "measured_at": "2026-11-29T06:00:00Z", "simulated": True,
                  "data": {"id": pid, "index": i, "first_nm": 380, "step_nm": 10, "values": list(cls.refl[i])}}
                 for i, pid in enumerate(cls.ids)]
        chart = RunData({"id": "01a20a70-bc32-7d8d-bc85-0000000000c8", "campaign": "chart-read", "params": {},
                         "status": "finished_ok", "instruments": []}, measurements_frame(items))
        run, _ = stored_verification()
        run.extra["chart_read"] = chart
        from colorlab.report import verification
        cls.html = verification.section(run)
        cls.cells = parse(cls.html)

    def independent(self, lamp):
        s = self.lamps[lamp]
        white = (s[:, None] * self.cmf).sum(axis=0)
        white = 100 * white / white[1]
        spectral = (self.refl * s) @ self.cmf * 100 / (s @ self.cmf[:, 1])
        d65 = self.lamps["D65"]
        albedo = ((self.refl * d65) @ self.cmf) @ IEC_XYZ_TO_SRGB.T
        albedo /= IEC_XYZ_TO_SRGB @ (d65 @ self.cmf)
        rgb = (albedo * (IEC_XYZ_TO_SRGB @ white)) @ np.linalg.inv(IEC_XYZ_TO_SRGB).T
        xyz = (self.refl @ self.cmf) / self.cmf.sum(axis=0) * white
        ref = lab(spectral, white)
        return delta_e00(lab(rgb, white), ref), delta_e00(lab(xyz, white), ref), xyz

    def test_per_patch_against_an_independent_computation(self):
        for lamp in self.lamps:
            rgb, xyz, _ = self.independent(lamp)
            got_rgb = np.array([self.cells.value(pid, f"rgb {lamp}") for pid in self.ids])
            got_xyz = np.array([self.cells.value(pid, f"xyz {lamp}") for pid in self.ids])
            # The printed matrix has 4 decimals and the tables come from another source: 0.02 ΔE00 covers both.
            np.testing.assert_allclose(got_rgb, rgb, atol=0.02, err_msg=lamp)
            np.testing.assert_allclose(got_xyz, xyz, atol=0.02, err_msg=lamp)
            self.assertAlmostEqual(self.cells.value(lamp, "rgb mean"), rgb.mean(), delta=0.01)
            self.assertAlmostEqual(self.cells.value(lamp, "rgb max"), rgb.max(), delta=0.02)
            worst = [t for a, t in self.cells.cells if a.get("data-row") == lamp and a.get("data-col") == "rgb worst"]
            if lamp != "D65":  # under D65 every error is rounding noise: no worst patch to agree on
                self.assertEqual(worst, [self.ids[int(np.argmax(rgb))]])
        # Physics, not this implementation: the RGB renderer's albedos are D65 colours, so under D65 it is exact.
        self.assertLess(self.cells.value("D65", "rgb max"), 0.02)

    def test_hostile_patch_ids_are_text(self):
        items = [{"seq": i + 1, "step": f"patch/{pid}", "instrument_id": "spectro", "quantity": "reflectance_spectrum",
                  "value": 50.0, "unit": "L*", "measured_at": "2026-11-29T06:00:00Z", "simulated": True,
                  "data": {"id": pid, "first_nm": 380, "step_nm": 10, "values": list(self.refl[i])}}
                 for i, pid in enumerate(["A1", "</td><script>x</script>", HOSTILE])]
        chart = RunData({"id": '"><img src=x>', "campaign": "chart-read", "params": {}, "status": "finished_ok",
                         "instruments": []}, measurements_frame(items))
        run, _ = stored_verification()
        run.extra["chart_read"] = chart
        from colorlab.report import verification
        html = verification.section(run).lower()
        self.assertNotIn("<script", html)
        self.assertNotIn("<img", html)
        self.assertIn("&lt;/td&gt;&lt;script&gt;x&lt;/script&gt;", html)

    def test_xyz_products_against_the_locus(self):
        from matplotlib.path import Path as MplPath
        c = self.cmf_1nm.loc[380:700].to_numpy(float)
        locus = MplPath(c[:, :2] / c.sum(axis=1, keepdims=True))
        for lamp in self.lamps:
            *_, xyz = self.independent(lamp)
            outside = int((~locus.contains_points(xyz[:, :2] / xyz.sum(axis=1, keepdims=True))).sum())
            self.assertEqual(self.cells.value(lamp, "xyz invalid"), outside, lamp)
        self.assertIn('data-products="560"', self.html)


if __name__ == "__main__":
    unittest.main()
