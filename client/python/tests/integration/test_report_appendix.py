"""The appendix's per-patch tables (16-20) in a characterize-camera run's report: each patch's ΔE*ab recomputed here
from the stored patch values and the reference run's L*a*b* with this test's own colour arithmetic and least squares
(test_report_characterization's), each stored black-box residual, and every published per-patch value read again
from the dissertation's text at the line it stands on."""
from __future__ import annotations

import os
import re
import unittest
from pathlib import Path

import numpy as np

import test_report_characterization as tc
from report_support import ReportCase, check_in_browser, make_report, parse

THESIS = Path(os.environ.get("COLORLAB_DISSERTATION", "/work/shared/seed/ulbricht-2006-dissertation.txt"))
CASES = (("tiff8", "8 bit", 1), ("jpeg", "jpg", 2), ("tiff16", "16 bit", 3))  # (format, column, field in the text)
# The report rounds its per-patch numbers to 4 decimals.
ROUNDED = 0.5e-4 + 1e-9


def text_rows(number):
    """{patch number: tab fields} of appendix Table <number>, found in the text by its caption (not by the lines
    the report cites): the rows numbered 1-140 since the previous table's caption."""
    if not THESIS.exists():
        raise unittest.SkipTest(f"{THESIS} absent")
    lines = THESIS.read_text().splitlines()
    cap = next(k for k, l in enumerate(lines) if l.startswith(f"Table {number}:") and "140 patches" in l)
    prev = max((k for k in range(cap) if re.match(r"^Table \d+:", lines[k])), default=0)
    start = max(prev, next(k for k, l in enumerate(lines) if l.startswith("E Detailed Results")))
    out = {}
    for l in lines[start + 1:cap]:
        f = l.split("\t")
        if re.fullmatch(r"\d+", f[0]) and len(f) > 2:
            out[int(f[0])] = f[1:]
    assert sorted(out) == list(range(1, 141)), number
    return out


def patch_id(n):
    return "ABCDEFGHIJKLMN"[(n - 1) % 14] + str((n - 1) // 14 + 1)


class AppendixReport(ReportCase):
    SEED = 9
    LAB_TOML = tc.LAB_TOML

    @classmethod
    def campaigns(cls, d):
        cls.ref = d.run_to_end("chart-read")["run_id"]
        cls.cc = d.run_to_end("characterize-camera", reference_run=cls.ref, frames=2, prior_exclude=["Canon_20D"])["run_id"]
        cls.path = make_report(d, [cls.cc], "appendix")
        cls.tables, _ = parse(cls.path)
        stored_ref = d.stored_measurements(cls.ref)
        cls.lab = {m["data"]["id"]: np.array(m["data"]["Lab"]) for m in stored_ref}
        cls.xyz = {m["data"]["id"]: np.array(m["data"]["XYZ"]) for m in stored_ref}
        cls.rgb = {}
        for m in d.stored_measurements(cls.cc):
            p = re.match(r"^patch/(\w+)/(\w+)$", m["step"])
            if p:
                cls.rgb.setdefault(p[1], {})[p[2]] = np.array(m["data"]["rgb"], float)
        cls.result = d.client.run(cls.cc)["summary"]["script"]

    def t(self, number):
        return self.tables[f"{tc.short(self.cc)}-table{number}"]

    def check(self, number, column, measured: dict, field):
        """measured: {patch id: value}; field: the text's tab field of this column (None: nothing published)."""
        t, text = self.t(number), text_rows(number)
        for n in range(1, 141):
            pid = patch_id(n)
            got = t[(pid, f"{column} measured", "patch")]
            self.assertAlmostEqual(got, measured[pid], delta=ROUNDED * max(1, abs(measured[pid])), msg=(number, column, pid))
            if field is None:
                self.assertNotIn((pid, f"{column} published", "patch"), t)
                continue
            published = float(text[n][field - 1])
            self.assertEqual(t[(pid, f"{column} published", "patch")], published, (number, column, pid))
            self.assertAlmostEqual(t[(pid, f"{column} diff", "patch")], measured[pid] - published,
                                   delta=2 * ROUNDED * max(1, abs(measured[pid])))
        if field is not None:
            d = np.array([measured[patch_id(n)] - float(text[n][field - 1]) for n in range(1, 141)])
            self.assertAlmostEqual(t[("mean-difference", f"{column} diff", "summary")], d.mean(), delta=1e-3)
            self.assertAlmostEqual(t[("mean-abs-difference", f"{column} diff", "summary")], np.abs(d).mean(), delta=1e-3)
            self.assertAlmostEqual(t[("largest-abs-difference", f"{column} diff", "summary")], np.abs(d).max(), delta=1e-3)

    def test_table16_camera_colour_space(self):
        m = tc.adobe_to_xyz_d50()
        for fmt, column, field in CASES:
            ids = sorted(self.rgb[fmt])
            rgb = np.stack([self.rgb[fmt][i] for i in ids]) / tc.SCALE[fmt]
            lab = tc.lab_d50((np.clip(rgb, 0, None) ** 2.19921875) @ m.T)
            de = np.linalg.norm(lab - np.stack([self.lab[i] for i in ids]), axis=1)
            self.check(16, column, dict(zip(ids, de)), field)

    def test_table17_matrix_shaper(self):
        for fmt, column, field in CASES:
            ids = sorted(self.rgb[fmt])
            lin = np.clip(np.stack([self.rgb[fmt][i] for i in ids]) / tc.SCALE[fmt], 0, None) ** 2.2
            xyz = np.stack([self.xyz[i] for i in ids]) / 100
            q, r = np.linalg.qr(lin)
            de = np.linalg.norm(tc.lab_d50(lin @ np.linalg.solve(r, q.T @ xyz)) - np.stack([self.lab[i] for i in ids]), axis=1)
            self.check(17, column, dict(zip(ids, de)), field)

    def test_tables_18_and_19_polynomials(self):
        ids = sorted(self.rgb["tiff8"])
        rgb = np.stack([self.rgb["tiff8"][i] for i in ids]) / 255.0
        lab = np.stack([self.lab[i] for i in ids])
        for n in range(1, 12):
            x = np.stack(tc.terms(n, rgb[:, 0], rgb[:, 1], rgb[:, 2]), axis=1)
            q, r = np.linalg.qr(x)
            de = dict(zip(ids, np.linalg.norm(x @ np.linalg.solve(r, q.T @ lab) - lab, axis=1)))
            # Table 18's printed columns 1-4 hold polynomials 2-5 (published.py); polynomial 1 has none.
            if n <= 5:
                self.check(18, f"poly {n}", de, None if n == 1 else n - 1)
            if n >= 5:
                self.check(19, f"poly {n}", de, n - 4)

    def test_table20_stored_residuals(self):
        per = self.result["formats"]["raw"]["approaches"]["black_box"]["residuals"]["patches"]["training"]
        for k, ch in enumerate("RGB"):
            self.check(20, ch, dict(zip(per["ids"], map(float, per[ch]))), k + 1)

    def test_report_in_a_browser(self):
        check_in_browser(self, self.path, [], "appendix")


if __name__ == "__main__":
    unittest.main()
