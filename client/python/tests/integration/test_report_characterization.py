"""The report of a characterize-camera run (chapter 7) on the simulated lab: Tables 9-13 recomputed here from
the patch values and reference L*a*b* as stored in the daemon's SQLite file (with this test's own colour
arithmetic and least squares), the daemon's stored statistics, the published numbers found in the
dissertation's text, and every figure shown by headless Chromium."""
from __future__ import annotations

import os
import re
import unittest
from pathlib import Path

import numpy as np

from report_support import ReportCase, check_in_browser, make_report, parse

THESIS = Path(os.environ.get("COLORLAB_DISSERTATION", "/work/shared/seed/ulbricht-2006-dissertation.txt"))
# The chart must span hundreds of pixels for the locator (as tests/integration/characterize_camera_test.cpp).
LAB_TOML = "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n"
SCALE = {"tiff8": 255.0, "jpeg": 255.0, "tiff16": 65535.0}


def short(run_id):
    return "r" + run_id.replace("-", "")[-12:]


def adobe_to_xyz_d50():
    """From Adobe RGB (1998)'s primaries and D65 white, adapted to D50 by Bradford."""
    xy = np.array([[0.64, 0.33], [0.21, 0.71], [0.15, 0.06]])
    prim = np.stack([xy[:, 0] / xy[:, 1], np.ones(3), (1 - xy.sum(1)) / xy[:, 1]])  # columns: XYZ of each primary
    w65 = np.array([0.3127 / 0.3290, 1.0, (1 - 0.3127 - 0.3290) / 0.3290])
    m65 = prim * np.linalg.solve(prim, w65)
    brad = np.array([[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367], [0.0389, -0.0685, 1.0296]])
    w50 = np.array([0.9642, 1.0, 0.8249])
    adapt = np.linalg.inv(brad) @ np.diag((brad @ w50) / (brad @ w65)) @ brad
    return adapt @ m65


def lab_d50(xyz):
    w = np.array([0.9642, 1.0, 0.8249])
    out = []
    for x in xyz / w:
        f = [v ** (1 / 3) if v > 216 / 24389 else (24389 / 27 * v + 16) / 116 for v in x]
        out.append([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])
    return np.array(out)


def terms(n, r, g, b):
    """§7.3's polynomial n, written out from the dissertation's list."""
    one = np.ones_like(r)
    base = [r, g, b, r * g, r * b, g * b]
    sq = [r ** 2, g ** 2, b ** 2]
    cube = [r ** 3, g ** 3, b ** 3]
    quart = [r ** 4, g ** 4, b ** 4]
    return {
        1: [r, g, b], 2: [r, g, b, r * g * b, one], 3: base, 4: base + [r * g * b, one], 5: base + sq,
        6: base + sq + [r * g * b, one], 7: base + sq + cube + [one],
        8: base + sq + [(r * g) ** 2, (r * b) ** 2, (g * b) ** 2, (r * g * b) ** 2] + cube
           + [(r * g) ** 3, (r * b) ** 3, (g * b) ** 3, one],
        9: base + sq + cube + quart + [one],
        10: base + [r * g * b] + sq + [(r * g) ** 2, (r * b) ** 2, (g * b) ** 2, (r * g * b) ** 2] + cube
            + [(r * g) ** 3, (r * b) ** 3, (g * b) ** 3, (r * g * b) ** 3] + quart
            + [(r * g) ** 4, (r * b) ** 4, (g * b) ** 4, (r * g * b) ** 4, one],
        11: base + sq + cube + quart + [r ** 5, g ** 5, b ** 5, one],
    }[n]


def five(v):
    return {"Min": v.min(), "Max": v.max(), "Median": np.median(v), "Mean": v.mean(), "Stdev": v.std(ddof=1)}


def thesis_stats(number):
    if not THESIS.exists():
        raise unittest.SkipTest(f"{THESIS} absent")
    lines = THESIS.read_text().splitlines()
    cap = next(k for k, l in enumerate(lines) if l.startswith(f"Table {number}:"))
    rows = {}
    for l in lines[cap - 8:cap]:
        f = l.split("\t")
        if f[0] in ("Min", "Max", "Median", "Mean", "Stdev"):
            rows[f[0]] = [float(x.split()[0]) for x in f[1:]]
    assert len(rows) == 5, (number, rows)
    return rows


class CharacterizationReport(ReportCase):
    SEED = 5
    LAB_TOML = LAB_TOML

    @classmethod
    def campaigns(cls, d):
        cls.ref = d.run_to_end("chart-read")["run_id"]
        cls.cc = d.run_to_end("characterize-camera", reference_run=cls.ref, frames=2, prior_exclude=["Canon_20D"])["run_id"]
        cls.path = make_report(d, [cls.cc], "characterize-camera")
        cls.tables, _ = parse(cls.path)
        stored_ref = d.stored_measurements(cls.ref)
        ref = {m["data"]["id"]: np.array(m["data"]["Lab"]) for m in stored_ref}
        cls.xyz = {m["data"]["id"]: np.array(m["data"]["XYZ"]) for m in stored_ref}
        cls.patches = {}
        for m in d.stored_measurements(cls.cc):
            p = re.match(r"^patch/(\w+)/(\w+)$", m["step"])
            if p:
                cls.patches.setdefault(p[1], []).append((p[2], np.array(m["data"]["rgb"]), ref[p[2]]))
        cls.result = d.client.run(cls.cc)["summary"]["script"]

    def t(self, name):
        return self.tables[f"{short(self.cc)}-{name}"]

    def test_table9_camera_colour_space(self):
        t = self.t("table9")
        published = thesis_stats(9)
        m = adobe_to_xyz_d50()
        for k, fmt in enumerate(("tiff8", "jpeg", "tiff16")):
            rows = self.patches[fmt]
            self.assertEqual(len(rows), 140)
            rgb = np.stack([r for _, r, _ in rows]) / SCALE[fmt]
            lab = lab_d50((np.clip(rgb, 0, None) ** 2.19921875) @ m.T)
            de = np.linalg.norm(lab - np.stack([l for _, _, l in rows]), axis=1)
            stored = self.result["formats"][fmt]["approaches"]["camera_colour_space"]["training"]
            # Three ways to the same number: this test's, the report's, the daemon's lcms (to its precision).
            self.assertAlmostEqual(de.mean(), stored["mean_de76"], delta=0.005)
            self.assertAlmostEqual(de.max(), stored["max_de76"], delta=0.005)
            for stat, v in five(de).items():
                self.assertAlmostEqual(t[(f"{stat}-measured", fmt, "measured")], v, delta=1e-9, msg=(fmt, stat))
                self.assertEqual(t[(f"{stat}-published", fmt, "published")], published[stat][k])
                self.assertAlmostEqual(t[(f"{stat}-diff", fmt, "difference")],
                                       t[(f"{stat}-measured", fmt, "measured")] - published[stat][k], places=9)
            self.assertEqual(t[("Mean-stored", fmt, "stored")], stored["mean_de76"])
            self.assertEqual(t[("Max-stored", fmt, "stored")], stored["max_de76"])

    def test_tables_11_and_12_polynomials(self):
        rows = self.patches["tiff8"]
        rgb = np.stack([r for _, r, _ in rows]) / 255.0
        lab = np.stack([l for _, _, l in rows])
        for number, ns in ((11, (1, 2, 3, 4)), (12, (5, 6, 7, 8, 9, 10, 11))):
            t = self.t(f"table{number}")
            published = thesis_stats(number)
            for k, n in enumerate(ns):
                x = np.stack(terms(n, rgb[:, 0], rgb[:, 1], rgb[:, 2]), axis=1)
                q, r = np.linalg.qr(x)
                fitted = x @ np.linalg.solve(r, q.T @ lab)
                de = np.linalg.norm(fitted - lab, axis=1)
                for stat, v in five(de).items():
                    self.assertAlmostEqual(t[(f"{stat}-measured", str(n), "measured")], v, places=5, msg=(n, stat))
                    self.assertEqual(t[(f"{stat}-published", str(n), "published")], published[stat][k])
            # More terms never fit the training patches worse (nested term sets).
            means = [t[("Mean-measured", str(n), "measured")] for n in ns]
            if number == 11:
                self.assertLessEqual(means[3], means[1] + 1e-9)  # 4 ⊃ 2
                self.assertLessEqual(means[3], means[2] + 1e-9)  # 4 ⊃ 3

    def test_table10_the_labs_matrix_shaper_rebuilt(self):
        t = self.t("table10")
        published = thesis_stats(10)
        for k, fmt in enumerate(("tiff8", "jpeg", "tiff16")):
            rows = self.patches[fmt]
            lin = np.clip(np.stack([r for _, r, _ in rows]) / SCALE[fmt], 0, None) ** 2.2
            xyz = np.stack([self.xyz[i] for i, _, _ in rows]) / 100
            q, r = np.linalg.qr(lin)
            lab = lab_d50(lin @ np.linalg.solve(r, q.T @ xyz))
            de = np.linalg.norm(lab - np.stack([l for _, _, l in rows]), axis=1)
            s = self.result["formats"][fmt]["approaches"]["icc_profile"]
            self.assertEqual((s["kind"], s["gamma"]), ("matrix/shaper", 2.2))
            # The daemon's profile through lcms, to its precision: the rebuilt one is the lab's.
            self.assertAlmostEqual(de.mean(), s["training"]["mean_de76"], delta=0.005)
            self.assertAlmostEqual(de.max(), s["training"]["max_de76"], delta=0.03)
            self.assertEqual(t[("Max-stored", fmt, "stored")], s["training"]["max_de76"])
            self.assertEqual(t[("Mean-stored", fmt, "stored")], s["training"]["mean_de76"])
            for stat, v in five(de).items():
                self.assertAlmostEqual(t[(f"{stat}-measured", fmt, "measured")], v, delta=1e-9, msg=(fmt, stat))
                self.assertEqual(t[(f"{stat}-published", fmt, "published")], published[stat][k])
                self.assertAlmostEqual(t[(f"{stat}-diff", fmt, "difference")], v - published[stat][k], delta=1e-9)

    def test_table13_from_the_stored_residuals(self):
        t = self.t("table13")
        published = thesis_stats(13)
        residuals = self.result["formats"]["raw"]["approaches"]["black_box"]["residuals"]
        res = residuals["training"]
        per_patch = residuals["patches"]["training"]
        self.assertEqual(len(set(per_patch["ids"])), 140)  # the SG's patches, each once, all in the reference
        self.assertTrue(set(per_patch["ids"]) <= set(self.xyz))
        for k, ch in enumerate("RGB"):
            # The statistics recomputed here from the stored per-patch residuals (|predicted − measured| counts).
            a = np.abs(np.asarray(per_patch[ch], float))
            own = {"Min": a.min(), "Max": a.max(), "Median": float(np.median(a)), "Mean": a.mean(),
                   "Stdev": a.std(ddof=1)}
            for stat in ("Min", "Max", "Median", "Mean", "Stdev"):
                self.assertEqual(t[(f"{stat}-stored", ch, "stored")], res[ch][stat.lower()])
                self.assertAlmostEqual(res[ch][stat.lower()], own[stat], delta=1e-9 * max(1.0, a.max()), msg=(ch, stat))
                self.assertEqual(t[(f"{stat}-published", ch, "published")], published[stat][k])
                self.assertAlmostEqual(t[(f"{stat}-diff", ch, "difference")],
                                       res[ch][stat.lower()] - published[stat][k], places=9)
            self.assertLessEqual(res[ch]["min"], res[ch]["mean"])

    def test_approaches_table_is_what_the_run_stored(self):
        t = self.t("approaches")
        n = 0
        for m in self.daemon.stored_measurements(self.cc):
            if m["step"].startswith("characterization/"):
                fmt, name = m["step"].split("/")[1:]
                self.assertEqual(t[(f"{fmt}-{name}", "CV mean ΔE00", "stored")], m["value"])
                self.assertEqual(t[(f"{fmt}-{name}", "training mean ΔE00", "stored")], m["data"]["training"]["mean"])
                n += 1
        self.assertEqual(n, 4 * 3)  # raw: icc, mapping, black box; each TIFF/JPEG: camera space, icc, mapping

    def test_opens_in_chromium_with_every_figure(self):
        figs = [f"{short(self.cc)}-{f}" for f in ("fig51", "fig52", "fig53", "fig54", "fig55", "fig56", "fig57", "fig58", "fig59", "fig60",
                                                   "blackbox")]
        check_in_browser(self, self.path, figs, "characterize-camera")


if __name__ == "__main__":
    unittest.main()
