"""Speed against accuracy and stability (issue 11), without a daemon: the Pareto front against a brute-force check,
the cheapest setting meeting a rule, CIEDE2000 against Sharma, Wu & Dalal's published pairs, cross-validation and
learning curves on synthetic charts whose answers follow from the mathematics, and the sections on synthetic runs."""
from __future__ import annotations

import unittest

import numpy as np
import pandas as pd

from colorlab.report import analyze, colour, pareto, stability, tradeoff
from colorlab.report.fetch import RunData


def brute_front(costs, errors):
    """A point is on the front iff no other point is at least as good in both and better in one."""
    n = len(costs)
    return sorted(i for i in range(n)
                  if not any(costs[j] <= costs[i] and errors[j] <= errors[i]
                             and (costs[j] < costs[i] or errors[j] < errors[i]) for j in range(n)))


class Front(unittest.TestCase):
    def test_against_brute_force(self):
        rng = np.random.default_rng(1)
        for trial in range(300):
            n = int(rng.integers(1, 25))
            # Integers: ties in cost, in error and whole duplicates happen.
            c = rng.integers(0, 8, n).astype(float)
            e = rng.integers(0, 8, n).astype(float)
            front = tradeoff.pareto_front(c, e)
            self.assertEqual(sorted(front), brute_front(c, e), (c, e))
            # Cheapest first, and along it the error falls strictly (except exact duplicates).
            self.assertEqual([c[i] for i in front], sorted(c[i] for i in front))
            for a, b in zip(front, front[1:]):
                self.assertTrue(e[b] < e[a] or (c[a], e[a]) == (c[b], e[b]))

    def test_continuous(self):
        rng = np.random.default_rng(2)
        c, e = rng.random(200), rng.random(200)
        self.assertEqual(sorted(tradeoff.pareto_front(c, e)), brute_front(c, e))

    def test_cheapest_meeting_the_rule(self):
        rng = np.random.default_rng(3)
        for _ in range(300):
            n = int(rng.integers(1, 15))
            c, e = rng.integers(0, 6, n).astype(float), rng.random(n)
            limit = float(rng.random())
            k = tradeoff.cheapest_meeting(c, e, limit)
            ok = [i for i in range(n) if e[i] <= limit]
            if not ok:
                self.assertIsNone(k)
                continue
            self.assertLessEqual(e[k], limit)
            self.assertEqual(c[k], min(c[i] for i in ok))
            self.assertEqual(e[k], min(e[i] for i in ok if c[i] == c[k]))
            # The cheapest point meeting a rule is always on the front.
            self.assertIn(k, tradeoff.pareto_front(c, e))

    def test_rule_boundary_is_inclusive(self):
        self.assertEqual(tradeoff.cheapest_meeting([1, 2, 3], [3.0, 2.0, 1.0], 2.0), 1)
        self.assertIsNone(tradeoff.cheapest_meeting([1, 2], [3.0, 2.5], 2.0))


class DeltaE00(unittest.TestCase):
    # Sharma, Wu & Dalal (2005), Table 1: pairs 1, 7, 13, 17, 25, 34.
    PAIRS = [((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
             ((50.0, 0.0, 0.0), (50.0, -1.0, 2.0), 2.3669),
             ((50.0, 2.4900, -0.0010), (50.0, -2.4900, 0.0011), 7.2195),
             ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
             ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644),
             ((2.0776, 0.0795, -1.1350), (0.9033, -0.0636, -0.5514), 0.9082)]

    def test_published_pairs(self):
        for a, b, want in self.PAIRS:
            self.assertAlmostEqual(float(tradeoff.delta_e00([a], [b])[0]), want, places=4, msg=(a, b))
            self.assertAlmostEqual(float(tradeoff.delta_e00([b], [a])[0]), want, places=4)


def synthetic_chart(n=140, seed=0):
    rng = np.random.default_rng(seed)
    rgb = rng.uniform(0.05, 0.95, (n, 3))
    m = np.array([[60.0, 40.0, -30.0], [30.0, -50.0, 45.0], [10.0, 15.0, -60.0]])
    return rgb, rgb @ m, m  # no constant: polynomial 1 (r g b) holds it exactly


class Models(unittest.TestCase):
    def test_design_term_counts(self):
        for n, p in zip(range(1, 12), (3, 5, 6, 8, 9, 11, 13, 20, 16, 29, 19)):
            self.assertEqual(colour.design(np.ones((2, 3)), n).shape, (2, p))

    def test_exact_model_cross_validates_to_zero(self):
        # L*a*b* exactly linear in r, g, b: polynomial 1 (r g b) holds it, so every fold predicts it exactly.
        rgb, lab, _ = synthetic_chart()
        self.assertLess(tradeoff.cross_validated(rgb, lab, 1).max(), 1e-9)
        # A superset of terms (polynomial 4 ⊃ 1) holds it too.
        self.assertLess(tradeoff.cross_validated(rgb, lab, 4).max(), 1e-8)

    def test_folds_partition(self):
        f = tradeoff.folds(140, 10)
        self.assertEqual(sorted(np.concatenate(f).tolist()), list(range(140)))
        self.assertTrue(all(len(x) == 14 for x in f))

    def test_learning_curve_exact_model_is_exact_from_p_patches(self):
        rgb, lab, _ = synthetic_chart()
        # Three unknowns per output: any 3 patches in general position determine the map.
        curve = tradeoff.learning_curve(rgb, lab, 1, [3, 5, 20, 100], draws=4)
        self.assertLess(max(curve), 1e-7)

    def test_learning_curve_falls_with_noise(self):
        """Noisy targets, the true model among the candidates: least squares' out-of-sample mean squared error is
        σ²(1 + p/(n − p − 1)) for Gaussian design — it falls with n towards the noise floor. ΔE00 is not ΔE*ab,
        so the test holds the trend and the floor's order, not the formula's value."""
        rng = np.random.default_rng(5)
        rgb, lab, _ = synthetic_chart(400, seed=5)
        sigma = 0.5
        noisy = lab + rng.normal(0, sigma, lab.shape)
        sizes = [12, 20, 40, 80, 160, 300]
        curve = tradeoff.learning_curve(rgb, noisy, 4, sizes, draws=30)
        self.assertGreater(curve[0], curve[-1])
        # Non-increasing within the Monte Carlo error (30 draws): no step up by more than 5 %.
        for a, b in zip(curve, curve[1:]):
            self.assertLessEqual(b, a * 1.05)
        # The floor: E|noise| = σ·2√2/√π ≈ 1.596σ in ΔE*ab, times (1 + p/(n − p − 1)) ≈ 1.03 at n = 300; ΔE00's
        # weights S_L, S_C, S_H are ≥ 1, its a* stretch (1 + G) ≤ 1.5 and its rotation term |R_T| ≤ 2 adds at most a
        # factor √2 (x² + y² + R_T·xy ≤ 2(x² + y²)), so ΔE00 ≤ 1.5·√2 ΔE*ab.
        self.assertLess(curve[-1], 1.596 * sigma * 1.05 * 1.5 * np.sqrt(2))
        self.assertGreater(curve[-1], 0.0)


def frame_run(noise: dict, start="2026-01-01T00:00:00Z", end_s=2.5, frames=25):
    rows = []
    for n, per in noise.items():
        for ch, v in per.items():
            rows.append({"step": f"noise/N{n}/{ch}", "value": v, "unit": "DN",
                         "measured_at": pd.Timestamp(start) + pd.Timedelta(seconds=end_s)})
    return RunData({"id": "00000000-0000-0000-0000-000000000001", "campaign": "frame-average", "started_at": start,
                    "params": {"frames": frames}, "summary": {"script": {"frames": frames}}}, pd.DataFrame(rows))


class Sections(unittest.TestCase):
    def test_frames_cheapest_n(self):
        # σ = 10/√N + a floor; the rule (≤ 1.10 σ25) picked by brute force below.
        base = {n: 10 / np.sqrt(n) + 2.0 for n in (1, 2, 4, 8, 16, 25)}
        d = pareto.frames_data(frame_run({n: {"R": v, "G": v} for n, v in base.items()}))
        limit = 1.10 * base[25]
        want = min(n for n in base if base[n] <= limit)
        self.assertEqual(d["frames"][d["chosen"]], want)
        self.assertAlmostEqual(d["per_frame"], 2.5 / 25)
        self.assertEqual(d["times"], [0.1 * n for n in d["frames"]])
        # Noise falls with every frame and time rises: every setting is on the front.
        self.assertEqual(d["front"], list(range(6)))

    def test_frames_section_markup(self):
        html = pareto.frames_section(frame_run({n: {"R": 5.0 / np.sqrt(n)} for n in (1, 2, 4, 8, 16, 25)}))
        self.assertIn('id="r000000000001-pareto-frames"', html)
        self.assertIn('id="r000000000001-fig-pareto-frames"', html)
        self.assertIn("data-chosen=", html)
        self.assertIn("<svg", html)

    def test_repeatability(self):
        rng = np.random.default_rng(9)
        groups = [100 + rng.normal(0, 0.4, 25) for _ in range(40)]
        pooled, mean, rel = pareto.repeatability(groups)
        dof = sum(len(g) - 1 for g in groups)
        self.assertAlmostEqual(pooled ** 2, sum(((g - g.mean()) ** 2).sum() for g in groups) / dof)
        # The pooled estimate of σ = 0.4 from 960 degrees of freedom: within 4 standard errors (σ/√(2·dof)).
        self.assertLess(abs(pooled - 0.4), 4 * 0.4 / np.sqrt(2 * dof))
        for n, r in zip(pareto.READINGS, rel):
            self.assertAlmostEqual(r, 100 * pooled / np.sqrt(n) / mean)
        self.assertIsNone(pareto.repeatability([[1.0], [2.0]]))


def xyz_to_lab_d50(xyz):
    """CIE L*a*b* against the ICC D50 white (96.42, 100, 82.49), written out here."""
    t = xyz / np.array([96.42, 100.0, 82.49])
    f = np.where(t > 216 / 24389, np.cbrt(t), (24389 / 27 * t + 16) / 116)
    return np.stack([116 * f[:, 1] - 16, 500 * (f[:, 0] - f[:, 1]), 200 * (f[:, 1] - f[:, 2])], axis=1)


def characterization_run(rgb01, xyz, lamp="D65", run_no=2):
    """A characterize-camera run of 8-bit patch values and its chart-read reference (XYZ and L*a*b*)."""
    ids = [f"P{k:03d}" for k in range(len(rgb01))]
    ref = RunData({"id": "00000000-0000-0000-0000-000000000009", "campaign": "chart-read"},
                  pd.DataFrame({"step": [f"patch/{i}" for i in ids], "data.id": ids,
                                "data.Lab": list(xyz_to_lab_d50(xyz)), "data.XYZ": list(xyz)}))
    run = RunData({"id": f"00000000-0000-0000-0000-00000000000{run_no}", "campaign": "characterize-camera",
                   "params": {"lamp": lamp}},
                  pd.DataFrame({"step": [f"patch/tiff8/{i}" for i in ids], "data.id": ids,
                                "data.rgb": list(rgb01 * 255.0)}))
    run.extra["reference"] = ref
    return run


class Stability(unittest.TestCase):
    """The report's stability section runs the analysis library's suite (colorlab analyze stability) on the stored
    values; on a chart whose XYZ is exactly linear in the camera values the answers follow from the mathematics."""

    @classmethod
    def setUpClass(cls):
        try:
            analyze.colorlab_binary()
        except analyze.AnalyzeFailed as e:
            raise unittest.SkipTest(str(e))
        rng = np.random.default_rng(3)
        cls.rgb = rng.uniform(0.05, 0.45, (60, 3))  # × 2 stays below full scale: no clipping
        cls.m = np.array([[41.2, 21.3, 1.9], [35.8, 71.5, 11.9], [18.0, 7.2, 95.0]])
        cls.cc = characterization_run(cls.rgb, cls.rgb @ cls.m)
        cls.a = stability.analyse(cls.cc)

    def case(self, method, kind, level=None):
        return stability._case(self.a, method, kind, level)

    def test_exact_linear_chart(self):
        for method in stability.METHODS:
            # Every method's terms include r, g, b: the linear truth is fitted exactly, held out or not.
            self.assertLess(self.case(method, "training")["max"], 1e-6, method)
            self.assertLess(self.case(method, "cross_validated")["max"], 1e-5, method)
        # poly:1 and rootpoly:2 are homogeneous of degree 1: at any exposure (below full scale) the XYZ ÷ k is exact.
        for method in ("poly:1", "rootpoly:2"):
            for k in stability.EXPOSURES:
                self.assertLess(self.case(method, "exposure", k)["max"], 1e-6, (method, k))
        # Noise makes the fit worse than none; 10 training patches cannot determine poly:10's 29 terms.
        self.assertGreater(self.case("poly:1", "noise", 0.02)["mean"], self.case("poly:1", "training")["mean"])
        few = self.case("poly:10", "training_patches", 10.0)
        self.assertEqual((few["fitted"], few["fails"], few["mean"]), (0.0, 1.0, None))
        verdict = next(v for v in self.a["suite"]["verdicts"] if v["method"] == "poly:10")
        self.assertEqual(verdict["fails"], 1.0)
        self.assertEqual(self.a["inputs"]["fmt"], "tiff8")

    def test_section_and_another_lamp(self):
        # The same chart under "TL84" with every value 1 % brighter: the lamp case is the exposure-like shift,
        # recomputed here with the exact linear model: XYZ(1.01 rgb) = 1.01 XYZ.
        other = characterization_run(self.rgb * 1.01, self.rgb @ self.m, lamp="TL84", run_no=3)
        self.cc.extra["other_lamps"] = [other]
        try:
            a = stability.analyse(self.cc)
            html = stability.section(self.cc)
        finally:
            self.cc.extra["other_lamps"] = []
        c = stability._case(a, "poly:1", "other_lamp", lamp="TL84")
        lab = xyz_to_lab_d50(self.rgb @ self.m)
        shifted = xyz_to_lab_d50(1.01 * (self.rgb @ self.m))
        expect = tradeoff.delta_e00(shifted, lab)  # checked against Sharma's pairs above
        self.assertAlmostEqual(c["mean"], expect.mean(), places=6)
        self.assertAlmostEqual(c["max"], expect.max(), places=6)
        for name in ("verdicts", "gamut", "noise", "learning", "exposure", "lamp"):
            self.assertIn(f'id="{self.cc.short}-stability-{name}"', html)
        self.assertIn("<svg", html)

    def test_binary_from_the_environment(self):
        import os
        saved = {k: os.environ.get(k) for k in ("COLORLAB_BIN", "COLORLAB_BIN_DIR")}
        try:
            os.environ["COLORLAB_BIN"] = "/x/colorlab"
            os.environ["COLORLAB_BIN_DIR"] = "/y"
            self.assertEqual(str(analyze.colorlab_binary()), "/x/colorlab")
            del os.environ["COLORLAB_BIN"]
            self.assertEqual(str(analyze.colorlab_binary()), "/y/colorlab")
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v


if __name__ == "__main__":
    unittest.main()
