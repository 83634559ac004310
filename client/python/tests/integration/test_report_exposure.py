"""The report of a dimmer-exposure run (Tables 7 and 8, §6.2's "which dimmer setting to use") on the simulated lab:
the interval lengths recomputed here from each dark border patch's value as stored in the daemon's SQLite file, the
dark border patches told from the stored photograph itself, the exposure shown to have reached the camera, the
physics of noise against exposure time, the published numbers found in the dissertation's text, and the plot shown
by headless Chromium."""
from __future__ import annotations

import math
import os
import unittest
from pathlib import Path

import numpy as np

from report_support import ReportCase, check_in_browser, make_report, parse

THESIS = Path(os.environ.get("COLORLAB_DISSERTATION", "/work/shared/seed/ulbricht-2006-dissertation.txt"))
# The chart must span hundreds of pixels for the locator (as test_report_characterization).
LAB_TOML = "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n"
LEVELS = (100.0, 50.0, 25.0, 15.0)
# The range of n = 14 independent normal values has standard deviation d3 · σ (the control-chart constant d3 for
# n = 14 is 0.763).
D3_14 = 0.763


def short(run_id):
    return "r" + run_id.replace("-", "")[-12:]


def border(pid: str) -> bool:
    return pid[0] in "AN" or pid[1:] in ("1", "10")


def thesis_fields(line: int):
    if not THESIS.exists():
        raise unittest.SkipTest(f"{THESIS} absent")
    return THESIS.read_text().splitlines()[line - 1].split("\t")


class DimmerExposureReport(ReportCase):
    LAB_TOML = LAB_TOML

    @classmethod
    def campaigns(cls, daemon):
        cls.run_id = daemon.run_to_end("dimmer-exposure")["run_id"]
        cls.stored = daemon.stored_measurements(cls.run_id)
        cls.report = make_report(daemon, [cls.run_id], "dimmer-exposure")
        cls.tables, cls.ids = parse(cls.report)
        cls.sid = short(cls.run_id)

    def by_step(self, prefix):
        return [m for m in self.stored if m["step"].startswith(prefix)]

    def exposure(self, level):
        return next(m["data"] for m in self.by_step(f"exposure/D{level:g}"))

    def photographed(self, fmt, level):
        f = self.exposure(level)["formats"][fmt]
        return dict(zip(f["ids"], np.array(f["values"], dtype=float)))

    def test_the_dark_border_patches_are_the_borders_darkest_fourteen(self):
        # Told from the stored photograph, not the script's list: the 14 border patches darkest in the raw's green.
        for level in LEVELS:
            values = self.photographed("raw", level)
            darkest = sorted((v[1], pid) for pid, v in values.items() if border(pid))[:14]
            want = {pid for _, pid in darkest}
            got = {m["data"]["id"] for m in self.by_step(f"dark/raw/D{level:g}/")}
            self.assertEqual(got, want, level)
            # And they are clearly a group of their own: the next border patch (a grey) is many times brighter.
            rest = sorted(v[1] for pid, v in values.items() if border(pid) and pid not in want)
            self.assertGreater(rest[0], 3 * max(values[p][1] for p in want))

    def test_stored_interval_lengths_are_recomputed_from_the_stored_patches(self):
        for fmt in ("tiff8", "raw"):
            for level in LEVELS:
                patches = np.array([m["data"]["rgb"] for m in self.by_step(f"dark/{fmt}/D{level:g}/")])
                self.assertEqual(patches.shape, (14, 3))
                # Each dark record is the photograph's own value of that patch.
                photo = self.photographed(fmt, level)
                for m in self.by_step(f"dark/{fmt}/D{level:g}/"):
                    np.testing.assert_array_equal(m["data"]["rgb"], photo[m["data"]["id"]])
                interval = next(m["data"]["rgb"] for m in self.by_step(f"interval/{fmt}/D{level:g}"))
                np.testing.assert_allclose(interval, patches.max(0) - patches.min(0), rtol=0, atol=1e-9)

    def test_report_tables_are_the_stored_numbers_beside_the_published(self):
        t8 = self.tables[f"{self.sid}-table8"]
        t7 = self.tables[f"{self.sid}-table7"]
        for k, level in enumerate(LEVELS):
            col = f"{level:g} %"
            interval = next(m["data"]["rgb"] for m in self.by_step(f"interval/tiff8/D{level:g}"))
            for c, ch in enumerate("RGB"):
                published = float(thesis_fields(1116 + c)[k + 1])
                self.assertAlmostEqual(t8[(f"{ch}-measured", col, "measured")], interval[c], places=9)
                self.assertEqual(t8[(f"{ch}-published", col, "published")], published)
                self.assertAlmostEqual(t8[(f"{ch}-diff", col, "difference")], interval[c] - published, places=9)
            e = self.exposure(level)
            printed = thesis_fields(1111)[k + 1]
            num, den = printed.split("/")
            self.assertAlmostEqual(t7[("exposure-measured", col, "measured")], e["shutter_s"], places=12)
            self.assertAlmostEqual(t7[("exposure-published", col, "published")], float(num) / float(den), places=12)
            self.assertEqual(t7[("aperture-published", col, "published")], float(thesis_fields(1110)[k + 1]))
            self.assertEqual(t7[("aperture-measured", col, "measured")], e["aperture_f"])

    def test_the_exposure_doubles_as_the_light_halves(self):
        # Table 7's rule: one doubling of the exposure time per halving of the dimmer level (15 % is within a third
        # of a stop of three halvings), at one aperture.
        t0 = self.exposure(100)["shutter_s"]
        for level in LEVELS:
            e = self.exposure(level)
            halvings = round(math.log2(100 / level))
            self.assertLess(abs(math.log2(e["shutter_s"] / t0) - halvings), 1 / 3 + 1e-9, level)
            self.assertEqual(e["aperture_f"], 4.0)

    def test_the_camera_got_the_light_times_the_exposure(self):
        # The raw is linear: the SG's 14 white border patches, relative to 100 %, read the exposure time times the
        # LS-110's luminance, relative to 100 % — so each photograph was taken with the time Table 7 gives.
        # Tolerance: the LS-110's repeatability (4 σ of two readings ≈ 0.6 %, docs/campaigns.md) plus the dimmed
        # tubes' flatter field between the meter's spot and the chart (the simulator's flattening: 3 % of the
        # shape at most, of a field varying by < 30 % across the cabinet: < 0.9 %): 1.5 %.
        base = self.exposure(100)
        white0 = None
        for level in LEVELS:
            e = self.exposure(level)
            values = self.photographed("raw", level)
            whites = sorted((v[1], pid) for pid, v in values.items() if border(pid))[-14:]
            white = np.mean([values[pid] for _, pid in whites], axis=0)
            white0 = white if white0 is None else white0
            want = (e["shutter_s"] * e["luminance"]) / (base["shutter_s"] * base["luminance"])
            np.testing.assert_allclose(white / white0, want, rtol=0.015, err_msg=str(level))

    def test_the_spread_does_not_fall_as_the_light_falls(self):
        # §6.2: with the exposure compensating, the photographs should be alike, and noise grows with the exposure
        # time (dark current, hot pixels), so the dark patches' interval length must not fall as the level falls.
        # It may seem to by chance: the range of 14 noisy values varies by D3_14 · σ, and σ, the noise of one
        # patch's value, is at most the 14 patches' own standard deviation s (their scatter is noise plus the
        # light's unevenness). So a fall beyond 3 · D3_14 · √(s_k² + s_100²) breaks the physics.
        # 8-bit values as Table 8; the raw relative to the dark patches' mean (the light times the exposure differs
        # from level to level by the dimmer's non-proportionality, which scales the raw's spread).
        for fmt, relative in (("tiff8", False), ("raw", True)):
            def spread(level):
                p = np.array([m["data"]["rgb"] for m in self.by_step(f"dark/{fmt}/D{level:g}/")])
                scale = p.mean(0) if relative else np.ones(3)
                return (p.max(0) - p.min(0)) / scale, p.std(0, ddof=1) / scale
            i0, s0 = spread(100)
            for level in LEVELS[1:]:
                i, s = spread(level)
                bound = 3 * D3_14 * np.sqrt(s ** 2 + s0 ** 2)
                self.assertTrue(np.all(i >= i0 - bound), f"{fmt} {level} %: {i} against {i0} ± {bound}")

    def test_the_result_lists_every_level_in_order(self):
        result = self.daemon.client.conn.get(f"/v1/runs/{self.run_id}")
        self.assertEqual([lv["level"] for lv in result["summary"]["script"]["levels"]], list(LEVELS))

    def test_report_in_a_browser(self):
        check_in_browser(self, self.report, [f"{self.sid}-table8-plot"], "dimmer-exposure")


if __name__ == "__main__":
    unittest.main()
