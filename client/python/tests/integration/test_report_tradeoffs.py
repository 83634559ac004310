"""Speed against accuracy and stability in the report (issue 11), on the simulated lab: frame-average, a small cabinet
grid with repeated readings, luminance-spot, chart-read and characterize-camera under two lamps; the report is made
through the CLI and its Pareto and stability tables are recomputed here from the measurements as stored in the
daemon's SQLite file, with this test's own CIEDE2000, least squares and brute-force Pareto fronts (not the report's
code). Times the report measures itself (its numpy refits) are taken from the markup; everything derived from them
(front, choice) is recomputed. Headless Chromium shows every new figure."""
from __future__ import annotations

import datetime as dt
import math
import re
import unittest

import numpy as np

import daemon_fixture
from report_support import check_in_browser, make_report, parse
from test_report_characterization import LAB_TOML, adobe_to_xyz_d50, lab_d50, terms

READINGS = (1, 2, 3, 4, 5, 8, 10, 16, 25)


def short(run_id):
    return "r" + run_id.replace("-", "")[-12:]


def seconds(ts: str) -> float:
    return dt.datetime.fromisoformat(ts.replace("Z", "+00:00")).timestamp()


def de00(x, y):
    """CIEDE2000 of one pair, written out from Sharma, Wu & Dalal (2005), scalar by scalar."""
    (l1, a1, b1), (l2, a2, b2) = x, y
    cbar = (math.hypot(a1, b1) + math.hypot(a2, b2)) / 2
    g = 0.5 * (1 - math.sqrt(cbar ** 7 / (cbar ** 7 + 25 ** 7)))
    a1, a2 = a1 * (1 + g), a2 * (1 + g)
    c1, c2 = math.hypot(a1, b1), math.hypot(a2, b2)
    h1 = math.degrees(math.atan2(b1, a1)) % 360 if c1 else 0.0
    h2 = math.degrees(math.atan2(b2, a2)) % 360 if c2 else 0.0
    if c1 * c2 == 0:
        dh, hbar = 0.0, h1 + h2
    else:
        dh = h2 - h1
        if dh > 180:
            dh -= 360
        elif dh < -180:
            dh += 360
        hbar = (h1 + h2) / 2 if abs(h1 - h2) <= 180 else ((h1 + h2 + 360) / 2 if h1 + h2 < 360 else (h1 + h2 - 360) / 2)
    dH = 2 * math.sqrt(c1 * c2) * math.sin(math.radians(dh) / 2)
    lbar, cb = (l1 + l2) / 2, (c1 + c2) / 2
    t = (1 - 0.17 * math.cos(math.radians(hbar - 30)) + 0.24 * math.cos(math.radians(2 * hbar))
         + 0.32 * math.cos(math.radians(3 * hbar + 6)) - 0.20 * math.cos(math.radians(4 * hbar - 63)))
    sl = 1 + 0.015 * (lbar - 50) ** 2 / math.sqrt(20 + (lbar - 50) ** 2)
    sc, sh = 1 + 0.045 * cb, 1 + 0.015 * cb * t
    rt = -2 * math.sqrt(cb ** 7 / (cb ** 7 + 25 ** 7)) * math.sin(math.radians(60 * math.exp(-((hbar - 275) / 25) ** 2)))
    dl, dc = (l2 - l1) / sl, (c2 - c1) / sc
    return math.sqrt(dl ** 2 + dc ** 2 + (dH / sh) ** 2 + rt * dc * dH / sh)


def de00s(p, q):
    return np.array([de00(a, b) for a, b in zip(p, q)])


def brute_front(costs, errors):
    n = len(costs)
    return sorted(i for i in range(n) if not any(
        costs[j] <= costs[i] and errors[j] <= errors[i] and (costs[j] < costs[i] or errors[j] < errors[i])
        for j in range(n)))


def cheapest(costs, errors, limit):
    ok = [i for i in range(len(costs)) if errors[i] <= limit]
    return min(ok, key=lambda i: (costs[i], errors[i])) if ok else None


def lsq(x, y):
    q, r = np.linalg.qr(x)
    return np.linalg.solve(r, q.T @ y)


class TradeoffsReport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        saved = daemon_fixture.LAB_TOML
        daemon_fixture.LAB_TOML = LAB_TOML
        try:
            cls.daemon = daemon_fixture.Daemon(time_scale=500, seed=5)
        finally:
            daemon_fixture.LAB_TOML = saved
        d = cls.daemon
        try:
            cls.fa = d.run_to_end("frame-average", frames=25)["run_id"]
            cls.grid = d.run_to_end("cabinet-grid", rows=2, cols=2, lamps=["D65"], dimmer_levels=[100, 50],
                                    readings=4, drift_check=False)["run_id"]
            cls.spot = d.run_to_end("luminance-spot", readings=12)["run_id"]
            cls.ref = d.run_to_end("chart-read")["run_id"]
            cls.cc = d.run_to_end("characterize-camera", reference_run=cls.ref, frames=2, formats=["tiff8"],
                                  prior_exclude=["Canon_20D"])["run_id"]
            cls.cc2 = d.run_to_end("characterize-camera", reference_run=cls.ref, frames=2, formats=["tiff8"],
                                   lamp="TL84", prior_exclude=["Canon_20D"])["run_id"]
            cls.runs = [cls.fa, cls.grid, cls.spot, cls.cc, cls.cc2]
            cls.path = make_report(d, cls.runs, "tradeoffs")
            cls.tables, cls.ids = parse(cls.path)
            cls.html = cls.path.read_text(encoding="utf-8")
            cls.stored = {r: d.stored_measurements(r) for r in cls.runs + [cls.ref]}
            cls.docs = {r: d.client.run(r) for r in cls.runs}
        except BaseException:
            d.cleanup()
            raise

    @classmethod
    def tearDownClass(cls):
        cls.daemon.cleanup()

    def t(self, run, name):
        return self.tables[f"{short(run)}-{name}"]

    def chosen(self, run, name):
        m = re.search(rf'id="{short(run)}-{name}".*?data-chosen="([^"]*)"', self.html, re.S)
        self.assertIsNotNone(m, name)
        return m[1]

    # ---- frames ----

    def test_frames_pareto(self):
        rows = [m for m in self.stored[self.fa] if m["step"].startswith("noise/N")]
        by = {}
        for m in rows:
            by.setdefault(int(m["step"].split("/")[1][1:]), []).append(m["value"])
        ns = sorted(by)
        self.assertEqual(ns, [1, 2, 4, 8, 16, 25])
        noise = [float(np.mean(by[n])) for n in ns]
        per = (min(seconds(m["measured_at"]) for m in rows) - seconds(self.docs[self.fa]["started_at"])) / 25
        times = [per * n for n in ns]
        t = self.t(self.fa, "pareto-frames")
        for k, n in enumerate(ns):
            self.assertAlmostEqual(t[("noise", str(n), "stored")], noise[k], places=9)
            self.assertAlmostEqual(t[("time", str(n), "measured")], times[k], delta=1e-6)
            self.assertEqual(t[("front", str(n), "derived")], 1.0 if k in brute_front(times, noise) else 0.0)
        self.assertEqual(self.chosen(self.fa, "pareto-frames"), str(ns[cheapest(times, noise, 1.10 * noise[-1])]))

    # ---- luminance ----

    def _repeatability(self, groups, per, run, name):
        dof = sum(len(g) - 1 for g in groups)
        pooled = math.sqrt(sum(((np.array(g) - np.mean(g)) ** 2).sum() for g in groups) / dof)
        mean = np.mean([np.mean(g) for g in groups])
        rel = [100 * pooled / math.sqrt(n) / mean for n in READINGS]
        times = [per * n for n in READINGS]
        t = self.t(run, name)
        for k, n in enumerate(READINGS):
            self.assertAlmostEqual(t[("repeatability", str(n), "derived")], rel[k], places=9)
            self.assertAlmostEqual(t[("time", str(n), "measured")], times[k], delta=1e-6)
            self.assertEqual(t[("front", str(n), "derived")], 1.0 if k in brute_front(times, rel) else 0.0)
        k = cheapest(times, rel, 0.1)
        self.assertEqual(self.chosen(run, name), "" if k is None else str(READINGS[k]))

    def test_cabinet_grid_readings_per_spot(self):
        recs = [m for m in self.stored[self.grid] if m["step"].startswith("L/")]
        self.assertEqual(len(recs), 2 * 2 * 2)
        groups = [m["data"]["readings"] for m in recs]
        self.assertTrue(all(len(g) == 4 for g in groups))
        span = max(seconds(m["measured_at"]) for m in recs) - seconds(self.docs[self.grid]["started_at"])
        self._repeatability(groups, span / sum(len(g) for g in groups), self.grid, "pareto-readings")

    def test_luminance_spot_readings(self):
        recs = [m for m in self.stored[self.spot] if m["step"].startswith("reading/")]
        self.assertEqual(len(recs), 12)
        gaps = np.diff(sorted(seconds(m["measured_at"]) for m in recs))
        self._repeatability([[m["value"] for m in recs]], float(np.median(gaps)), self.spot, "pareto-readings")

    # ---- characterization ----

    def chart(self, run):
        ref = {m["data"]["id"]: m["data"] for m in self.stored[self.ref]}
        rows = [(m["step"].split("/")[2], np.array(m["data"]["rgb"], float)) for m in self.stored[run]
                if re.match(r"^patch/tiff8/\w+$", m["step"])]
        self.assertEqual(len(rows), 140)
        ids = [i for i, _ in rows]
        return (ids, np.stack([r for _, r in rows]) / 255.0, np.stack([ref[i]["Lab"] for i in ids]),
                np.stack([ref[i]["XYZ"] for i in ids]))

    def test_stored_models_pareto(self):
        res = self.docs[self.cc]["summary"]["script"]["formats"]["tiff8"]["approaches"]
        models = [("camera colour space", 0.0, res["camera_colour_space"]["cv"]["mean"]),
                  ("ICC matrix/shaper", 10.0, res["icc_profile"]["cv"]["mean"])]
        models += [(f"{c['method']}→{c['target']}", c["parameters"], c["cv_mean"])
                   for c in res["adapted_mapping"]["candidates"]]
        t = self.t(self.cc, "pareto-models")
        params, cv = [m[1] for m in models], [m[2] for m in models]
        front = brute_front(params, cv)
        for k, (label, p, e) in enumerate(models):
            self.assertEqual(t[(label, "parameters", "stored")], p)
            self.assertEqual(t[(label, "CV mean ΔE00", "stored")], e)
            self.assertEqual(t[(label, "Pareto front", "stored")], 1.0 if k in front else 0.0, label)
        tol = res["adapted_mapping"].get("tolerance_de00", 0.1)
        self.assertEqual(self.chosen(self.cc, "pareto-models"), models[cheapest(params, cv, min(cv) + tol)][0])

    def test_refitted_polynomials(self):
        ids, rgb, lab, _ = self.chart(self.cc)
        t = self.t(self.cc, "pareto-refits")
        idx = np.arange(140)
        cvs, costs = [], []
        for n in range(1, 12):
            x = np.stack(terms(n, rgb[:, 0], rgb[:, 1], rgb[:, 2]), axis=1)
            pred = np.empty_like(lab)
            for f in range(10):
                test, train = idx % 10 == f, idx % 10 != f
                pred[test] = x[test] @ lsq(x[train], lab[train])
            cv = de00s(pred, lab).mean()
            training = de00s(x @ lsq(x, lab), lab).mean()
            self.assertAlmostEqual(t[(f"poly{n}", "10-fold CV mean ΔE00", "model")], cv, places=6, msg=n)
            self.assertAlmostEqual(t[(f"poly{n}", "training mean ΔE00", "model")], training, places=6, msg=n)
            self.assertEqual(t[(f"poly{n}", "terms", "model")], x.shape[1])
            cost = t[(f"poly{n}", "fit (ms)", "model")] + t[(f"poly{n}", "apply (ms)", "model")]
            self.assertGreater(cost, 0)
            cvs.append(cv)
            costs.append(cost)
        front = brute_front(costs, cvs)
        for k in range(11):
            self.assertEqual(t[(f"poly{k + 1}", "Pareto front", "model")], 1.0 if k in front else 0.0)
        self.assertEqual(self.chosen(self.cc, "pareto-refits"), str(cheapest(costs, cvs, min(cvs) + 0.1) + 1))
        # Training-set size: the best-cross-validating polynomial's learning curve (random draws: its values are the
        # report's; the front and the choice are recomputed from them), up to 9/10 of the chart.
        best = int(np.argmin(cvs)) + 1
        self.assertIn(f"polynomial {best} (the best 10-fold CV", self.html)
        t = self.t(self.cc, "pareto-patches")
        curve = sorted((int(c), v) for (r, c, _), v in t.items() if r == "error")
        sizes, errs = [c for c, _ in curve], [v for _, v in curve]
        self.assertEqual(sizes[-1], 126)
        self.assertTrue(all(s > len(terms(best, *rgb.T)) for s in sizes))
        self.assertLess(errs[-1], errs[0])
        front = brute_front(sizes, errs)
        for k, s in enumerate(sizes):
            self.assertEqual(t[("front", str(s), "derived")], 1.0 if k in front else 0.0)
        self.assertEqual(self.chosen(self.cc, "pareto-patches"), str(sizes[cheapest(sizes, errs, 1.10 * errs[-1])]))

    # ---- stability ----

    def models(self):
        """The stability suite's methods written out here: (key, fit(rgb, lab, xyz), apply(rgb, m))."""
        adobe = adobe_to_xyz_d50()
        out = [("space", lambda r, l, x: None, lambda r, m: lab_d50((np.clip(r, 0, 1) ** 2.19921875) @ adobe.T)),
               ("icc", lambda r, l, x: lsq(np.clip(r, 0, None) ** 2.2, x / 100),
                lambda r, m: lab_d50((np.clip(r, 0, None) ** 2.2) @ m))]
        for n in (1, 6, 10):
            design = (lambda n: lambda r: np.stack(terms(n, r[:, 0], r[:, 1], r[:, 2]), axis=1))(n)
            out.append((f"poly{n}", (lambda d: lambda r, l, x: lsq(d(r), l))(design),
                        (lambda d: lambda r, m: d(r) @ m)(design)))
        return out

    def test_stability_gamut_and_exposure(self):
        ids, rgb, lab, xyz = self.chart(self.cc)
        gam, exp = self.t(self.cc, "stability-gamut"), self.t(self.cc, "stability-exposure")
        chroma = np.hypot(lab[:, 1], lab[:, 2])
        vivid = chroma >= np.quantile(chroma, 0.9)
        idx = np.arange(140)
        for key, fit, apply in self.models():
            pred = np.empty_like(lab)
            for f in range(10):
                test, train = idx % 10 == f, idx % 10 != f
                pred[test] = apply(rgb[test], fit(rgb[train], lab[train], xyz[train]))
            e = de00s(pred, lab)
            self.assertAlmostEqual(gam[(key, "CV mean", "model")], e.mean(), places=6, msg=key)
            self.assertAlmostEqual(gam[(key, "CV mean, most chromatic 10 %", "model")], e[vivid].mean(), places=6)
            self.assertAlmostEqual(gam[(key, "CV max", "model")], e.max(), places=6)
            self.assertAlmostEqual(gam[(key, "worst: C*ab", "model")], chroma[np.argmax(e)], places=6)
            m = fit(rgb, lab, xyz)
            for s in (0.8, 1.0, 1.25):
                e = de00s(apply(np.clip(rgb * s, 0, 1), m), lab)
                self.assertAlmostEqual(exp[(key, f"mean ×{s:g}", "model")], e.mean(), places=6, msg=(key, s))
                self.assertAlmostEqual(exp[(key, f"max ×{s:g}", "model")], e.max(), places=6)
            # Noise ×0 is the training error; then it grows (5 draws each: the ×8 column above the ×0 one).
            noise = self.t(self.cc, "stability-noise")
            self.assertAlmostEqual(noise[(key, "×0", "model")], exp[(key, "mean ×1", "model")], places=6)
            self.assertGreater(noise[(key, "×8", "model")], noise[(key, "×0", "model")])

    def test_stability_learning_curve_trend(self):
        t = self.t(self.cc, "stability-learning")
        for key in ("icc", "poly1", "poly6", "poly10"):
            row = sorted((int(c), v) for (r, c, _), v in t.items() if r == key)
            self.assertGreaterEqual(len(row), 3, key)
            # Trained on the most patches it does better than on the fewest (more patches than parameters).
            self.assertLess(row[-1][1], row[0][1], key)
        self.assertNotIn(("space", "12", "model"), t)  # nothing fitted, no curve

    def test_stability_another_lamp(self):
        ids, rgb, lab, xyz = self.chart(self.cc)
        ids2, rgb2, _, _ = self.chart(self.cc2)
        self.assertEqual(ids, ids2)
        t = self.t(self.cc, "stability-lamp")
        for key, fit, apply in self.models():
            e = de00s(apply(rgb2, fit(rgb, lab, xyz)), lab)
            self.assertAlmostEqual(t[(key, "TL84 mean", "model")], e.mean(), places=6, msg=key)
            self.assertAlmostEqual(t[(key, "TL84 max", "model")], e.max(), places=6)
        # And the TL84 run's section has the D65 run as its other lamp.
        self.assertIn(f"{short(self.cc2)}-stability-lamp", self.tables)

    def test_opens_in_chromium(self):
        figs = [f"{short(self.fa)}-fig-pareto-frames", f"{short(self.grid)}-fig-pareto-readings",
                f"{short(self.spot)}-fig-pareto-readings", f"{short(self.cc)}-fig-pareto-models"]
        figs += [f"{short(self.cc)}-fig-stability-{n}" for n in ("gamut", "noise", "learning", "exposure", "lamp")]
        check_in_browser(self, self.path, figs, "tradeoffs")


if __name__ == "__main__":
    unittest.main()
