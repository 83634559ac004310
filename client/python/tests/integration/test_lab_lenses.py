"""lenses() against a real colorlabd whose configuration holds two [[lens]] tables: the frame has what the
configuration says (values written here), and agrees with the C++ CLI's reading of the same route
(`colorlab --json lens list`)."""
import json
import subprocess
import unittest

from daemon_fixture import BIN_DIR, Daemon

LENSES = """
[[lens]]
camera = "Canon EOS 20D #1"
lens = "EF 50mm f/1.8 II"
focal_length_mm = 50
width_px = 3504
height_px = 2336
fx = 7790.2
fy = 7791.0
cx = 1755.3
cy = 1160.8
k1 = -0.081
k2 = 0.12
sigma = { fx = 3.1, fy = 3.0, cx = 2.2, cy = 1.9, k1 = 0.002, k2 = 0.02 }
rms_px = 0.4
photographs = 8
points = 1100
source = "colorlab lens calibrate over 8 photographs"
date = "2026-11-29"

[[lens]]
camera = "simulated DSLR"
lens = "31 mm"
width_px = 640
height_px = 428
fx = 900.5
fy = 901.4
cx = 321.5
cy = 212.0
k1 = 0.0
k2 = 0.0
sigma = { fx = 5.0, fy = 5.1, cx = 2.0, cy = 2.5, k1 = 0.01, k2 = 0.05 }
source = "test"
date = "2026-11-30"
"""


class LabLensesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon(extra=LENSES)
        cls.addClassCleanup(cls.daemon.cleanup)
        cls.lab = cls.daemon.client

    def test_the_configured_calibrations_as_a_frame(self):
        df = self.lab.lenses().set_index("name")
        big = df.loc["Canon EOS 20D #1 / EF 50mm f/1.8 II @ 50 mm"]
        self.assertEqual((big["width_px"], big["height_px"]), (3504, 2336))
        self.assertEqual((big["fx"], big["fy"], big["cx"], big["cy"], big["k1"], big["k2"]),
                         (7790.2, 7791.0, 1755.3, 1160.8, -0.081, 0.12))
        self.assertEqual((big["sigma.fx"], big["sigma.k2"]), (3.1, 0.02))
        self.assertEqual((big["photographs"], big["points"], big["date"]), (8, 1100, "2026-11-29"))
        small = df.loc["simulated DSLR / 31 mm"]
        self.assertEqual((small["width_px"], small["height_px"], small["fx"], small["k1"], small["k2"]),
                         (640, 428, 900.5, 0.0, 0.0))
        self.assertEqual(small["sigma.cy"], 2.5)

    def test_agrees_with_the_cli(self):
        p = subprocess.run([str(BIN_DIR / "colorlab"), "--socket", self.daemon.endpoint["unix_socket"], "--json",
                            "lens", "list"], capture_output=True, text=True, timeout=120)
        self.assertEqual(p.returncode, 0, p.stderr)
        cli = json.loads(p.stdout)
        items = cli["items"] if isinstance(cli, dict) else cli
        df = self.lab.lenses().set_index("name")
        self.assertEqual(sorted(df.index), sorted(i["name"] for i in items))
        for item in items:
            row = df.loc[item["name"]]
            for key in ("width_px", "height_px", "fx", "fy", "cx", "cy", "k1", "k2", "source", "date"):
                self.assertEqual(row[key], item[key], f"{item['name']}: {key}")
            for key, value in item["sigma"].items():
                self.assertEqual(row[f"sigma.{key}"], value, f"{item['name']}: sigma.{key}")


if __name__ == "__main__":
    unittest.main()
