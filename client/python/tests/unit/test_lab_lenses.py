"""lenses(): GET /v1/lab/lenses as a DataFrame, one row per calibration with its σ as sigma.* columns; none
configured gives an empty frame with the documented columns; a refusal is the client's typed error."""
import unittest

import colorlab
from colorlab.lab import LENS_COLUMNS
from fake_daemon import FakeDaemon

LENS = {"name": "Canon EOS 20D #1 / EF 50mm f/1.8 II @ 50 mm", "camera": "Canon EOS 20D #1", "lens": "EF 50mm f/1.8 II",
        "focal_length_mm": 50, "focus": "1.2 m", "width_px": 3504, "height_px": 2336, "fx": 7790.2, "fy": 7791.0,
        "cx": 1755.3, "cy": 1160.8, "k1": -0.081, "k2": 0.12,
        "sigma": {"fx": 3.1, "fy": 3.0, "cx": 2.2, "cy": 1.9, "k1": 0.002, "k2": 0.02}, "rms_px": 0.4,
        "photographs": 8, "points": 1100, "source": "colorlab lens calibrate", "date": "2026-11-29"}
SMALL = dict(LENS, name="sim / 31 mm", camera="sim", lens="31 mm", focal_length_mm=None, focus="", width_px=1752,
             height_px=1168, fx=2450.0, fy=2452.45, cx=879.0, cy=581.0,
             sigma={"fx": 13.8, "fy": 13.2, "cx": 6.0, "cy": 7.3, "k1": 0.0156, "k2": 0.123})


class LensesTest(unittest.TestCase):
    def test_each_calibration_is_a_row_with_its_uncertainty(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/lab/lenses")] = lambda h: h.send_json(200, {"items": [LENS, SMALL]})
            lab = self.enterContext(colorlab.Client(fake.url))
            df = lab.lenses()
            self.assertEqual(fake.requests_to("GET", "/v1/lab/lenses")[-1][1], "/v1/lab/lenses")
        self.assertEqual(len(df), 2)
        self.assertEqual(sorted(df.columns), sorted(LENS_COLUMNS))
        for row, item in zip(df.to_dict("records"), (LENS, SMALL)):
            for key, value in item.items():
                if key == "sigma":
                    for k, s in value.items():
                        self.assertEqual(row[f"sigma.{k}"], s, k)
                elif value is None:
                    self.assertTrue(row[key] is None or row[key] != row[key], key)  # None or NaN
                else:
                    self.assertEqual(row[key], value, key)
        # Choosing the calibration of a photograph's size, as the report does, is a plain filter.
        fit = df[(df["width_px"] == 1752) & (df["height_px"] == 1168)]
        self.assertEqual(fit["name"].tolist(), ["sim / 31 mm"])

    def test_no_calibration_configured_is_an_empty_frame_with_the_columns(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/lab/lenses")] = lambda h: h.send_json(200, {"items": []})
            df = self.enterContext(colorlab.Client(fake.url)).lenses()
        self.assertTrue(df.empty)
        self.assertEqual(list(df.columns), LENS_COLUMNS)

    def test_a_refusal_is_raised(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/lab/lenses")] = lambda h: h.send_problem(
                401, "unauthorized", "Unauthorized", "this listener needs an API key")
            with self.assertRaises(colorlab.Unauthorized):
                self.enterContext(colorlab.Client(fake.url)).lenses()


if __name__ == "__main__":
    unittest.main()
