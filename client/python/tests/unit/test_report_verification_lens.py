"""The report's maps over the photograph placed through the lens calibration (docs/verify.md "Report"), without a
daemon and without rasterising: where the overlay puts each patch and floor cell is compared with this test's own
camera — a pinhole posed in 3-D whose image is then distorted by OpenCV's radial model (k1, k2), written here from
the model's definition — not with the report's own undistort-homography-distort. The misplacement in photograph
pixels is measured with the lens and without it (the old pinhole homography of the distorted corners)."""
from __future__ import annotations

import unittest

import numpy as np
import pandas as pd

from colorlab.report import verification
from colorlab.report import verification_lens as lens_mod
from colorlab.report import verification_overlay as overlay
from colorlab.report.fetch import RunData
from colorlab.report.verification_photo import Photo
from colorlab.tables import measurements_frame
from test_report_verification_photo import FakeClient, comparison, measurement, png

W, H = 3504, 2336
SIDE = 15.0 / 19.0
PITCH_MM = 19.0


def camera(eye, target, f, cx, cy, k1, k2, aspect=1.0):
    """World points (mm) → photograph pixels: a pinhole at eye looking at target (image y down), then the radial
    distortion about (cx, cy) as OpenCV defines it: x_d = x (1 + k1 r² + k2 r⁴) in coordinates divided by f."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)

    def project(p):
        d = np.asarray(p, float) - eye
        a, b = d @ x / (d @ z), d @ y / (d @ z)
        r2 = a * a + b * b
        k = 1 + k1 * r2 + k2 * r2 * r2
        return np.array([cx + f * a * k, cy + f * aspect * b * k])
    return project


LENS = {"fx": 2400.0, "fy": 2402.4, "cx": W / 2 - 0.5 + 4.0, "cy": H / 2 - 0.5 - 3.0, "k1": -0.10, "k2": 0.02}
FLOOR_CAM = camera([600.0, -700.0, 900.0], [600.0, 300.0, 0.0], LENS["fx"], LENS["cx"], LENS["cy"], LENS["k1"],
                   LENS["k2"], LENS["fy"] / LENS["fx"])
CHART_CAM = camera([140.0, -420.0, 560.0], [140.0, -98.0, 0.0], LENS["fx"], LENS["cx"], LENS["cy"], LENS["k1"],
                   LENS["k2"], LENS["fy"] / LENS["fx"])


def floor_truth(x, y):
    return FLOOR_CAM([x, y, 0.0])


def chart_truth(gx, gy):
    return CHART_CAM([gx * PITCH_MM, -gy * PITCH_MM, 0.0])


def floor_photo(lens):
    corners = np.array([floor_truth(x, y) for x, y in ((0, 0), (1200, 0), (1200, 600), (0, 600))])
    return Photo(np.zeros((4, 6)), W, H, corners, "fl", "b" * 64, "P/D65/D100", {"spot_mm": 20.0}, lens)


def chart_photo(lens):
    gw, gh = 13 + SIDE, 9 + SIDE
    corners = np.array([chart_truth(x, y) for x, y in ((0, 0), (gw, 0), (gw, gh), (0, gh))])
    return Photo(np.zeros((4, 6)), W, H, corners, "cc", "a" * 64, "chart/raw", {}, lens)


def named(lens, name):
    return dict(lens, name=name)


class PlacementTest(unittest.TestCase):
    def test_the_camera_spans_the_frame(self):
        """The floor's front corners near the frame's edges, where the distortion is largest (else this test could
        not tell the placements apart)."""
        front = [floor_truth(0, 0), floor_truth(1200, 0)]
        self.assertTrue(all(0 <= p[0] < W and 0 <= p[1] < H for p in front), front)
        self.assertLess(front[0][0], 0.15 * W)
        self.assertGreater(front[1][0], 0.85 * W)

    def test_undistort_inverts_distort_and_refuses_past_the_fold(self):
        pts = np.array([[0.0, 0.0], [W - 1.0, H - 1.0], [LENS["cx"], LENS["cy"]], [100.0, 2000.0]])
        back = lens_mod.distort(named(LENS, ""), lens_mod.undistort(named(LENS, ""), pts))
        self.assertLess(float(np.abs(back - pts).max()), 1e-9)
        with self.assertRaises(ValueError):
            lens_mod.undistort({"fx": 1000, "fy": 1000, "cx": 1000, "cy": 1000, "k1": -2.0, "k2": 0.0}, [[1600, 1000]])

    def test_floor_spots_and_cells_land_where_the_camera_sees_them(self):
        with_lens = overlay.floor_placement(floor_photo(named(LENS, "bench")))
        pinhole = overlay.floor_placement(floor_photo(None))
        centres = [((c + 0.5) * 60, (r + 0.5) * 54) for r in range(8) for c in range(20)]
        truth = np.array([floor_truth(x, y) for x, y in centres])
        after = float(np.hypot(*(with_lens(centres) - truth).T).max())
        before = np.hypot(*(pinhole(centres) - truth).T)
        print(f"[ report floor k1 {LENS['k1']} k2 {LENS['k2']} ] spot centres off the camera's: {before.max():.2f} px "
              f"as a pinhole (80 LS-110 spots: {before.reshape(8, 20)[:, :10].max():.2f} px), {after:.1e} px through "
              "the lens")
        self.assertLess(after, 1e-6)
        self.assertGreater(before.max(), 2.0)
        self.assertIn("bench", with_lens.how)
        self.assertIn("pinhole", pinhole.how)

    def test_the_figure_draws_each_cell_on_the_cameras_outline(self):
        photo = floor_photo(named(LENS, "bench"))
        items = [comparison("light_floor", f"r{r}c{c}", 0.0, False) for r in range(8) for c in range(20)]
        fig, panels = overlay.floor_figure(photo, {"light_floor": items})
        ax = panels[0][0]
        cells = [p for p in ax.patches if len(p.get_xy()) > 4]
        self.assertEqual(len(cells), 160)
        worst = 0.0
        for (r, c), poly in zip([(r, c) for r in range(8) for c in range(20)], cells):
            # The outline walks the cell's edges front-left first, each cut in 8: those floor points, as the camera
            # sees them.
            x0, y0 = c * 60.0, r * 54.0
            corners = [(x0, y0), (x0 + 60, y0), (x0 + 60, y0 + 54), (x0, y0 + 54)]
            walk = [np.add(a, k / 8 * np.subtract(b, a)) for a, b in zip(corners, corners[1:] + corners[:1])
                    for k in range(8)]
            truth = np.array([floor_truth(*q) for q in walk])
            drawn = poly.get_xy()[:len(walk)]
            worst = max(worst, float(np.hypot(*(drawn - truth).T).max()))
        print(f"[ report floor figure ] 160 cells' outlines, 32 points each, off the camera's by {worst:.1e} px at most")
        self.assertLess(worst, 1e-6)
        import matplotlib.pyplot as plt
        plt.close(fig)

    def test_chart_patches_land_where_the_camera_sees_them(self):
        with_lens = overlay.chart_placement(chart_photo(named(LENS, "bench")))
        pinhole = overlay.chart_placement(chart_photo(None))
        centres = [(c + SIDE / 2, r + SIDE / 2) for r in range(10) for c in range(14)]
        truth = np.array([chart_truth(x, y) for x, y in centres])
        after = float(np.hypot(*(with_lens(centres) - truth).T).max())
        before = float(np.hypot(*(pinhole(centres) - truth).T).max())
        print(f"[ report chart ] patch centres off the camera's: {before:.2f} px as a pinhole, {after:.1e} px "
              "through the lens (the corners being the photographed ones)")
        self.assertLess(after, 1e-6)
        self.assertGreater(before, 1.0)


class ChoiceTest(unittest.TestCase):
    def build(self, calibrations, placement):
        client = FakeClient()
        client.lenses = lambda: pd.DataFrame(calibrations)
        client.docs["cc"] = {"id": "cc", "campaign": "characterize-camera"}
        photo = chart_photo(None)
        client.rows["cc"] = [measurement(1, "chart/raw", 1.0, {"format": "raw", "corners": photo.corners.tolist(),
                                                              "width": W, "height": H})]
        client.bytes["a" * 64] = png(np.full((H // 8, W // 8), 0.3))
        client.kept["cc"] = [{"name": "camera.photograph_chart#3/preview", "sha256": "a" * 64, "kind": "preview",
                              "step": "chart/raw", "media_type": "image/png"}]
        client.docs["fl"] = {"id": "fl", "campaign": "floor-luminance"}
        fp = floor_photo(None)
        rows = [measurement(1, "P/D65/D100", 1.0, {"width": W, "height": H, "corners_px": fp.corners.tolist(),
                                                    "spot_mm": 20})]
        rows += [measurement(2 + c, f"F/D65/D100/r0c{c}", 100.0, {"row": 0, "col": c}) for c in range(3)]
        client.rows["fl"] = rows
        client.bytes["b" * 64] = png(np.full((H // 8, W // 8), 0.5))
        client.kept["fl"] = [{"name": "camera.photograph_floor#2/preview", "sha256": "b" * 64, "kind": "preview",
                              "step": "D65 100%", "media_type": "image/png"}]
        comps = [comparison("colour_7_3", "A1", 0.5, False)]
        comps += [comparison("light_floor", f"r0c{c}", 0.0, False, measured=100.0) for c in range(3)]
        items = [measurement(k + 1, f"{x['kind']}/{x['where']}", x["difference"], x) for k, x in enumerate(comps)]
        params = {"rendering": "box.exr", "against": ["cc", "fl"], "scale": 1.0, "k": 2}
        if placement:
            params["placement"] = placement
        run = RunData({"id": "01a20a70-bc32-7d8d-bc85-0000000000f3", "campaign": "verify", "status": "finished_ok",
                       "params": params, "summary": {}}, measurements_frame(items))
        verification.link(client, [run])
        return run.extra["photos"]

    def calibration(self, name, width=W, height=H, **over):
        return dict(LENS, name=name, width_px=width, height_px=height, **over)

    def test_the_stored_placement_then_the_lab_calibration_of_the_photographs_size(self):
        stored = {"light": {"model": "lens calibration", "lens": dict(LENS, name="stored", width_px=W, height_px=H),
                           "how": "…"}}
        photos = self.build([self.calibration("lab"), self.calibration("other size", 1752, 1168)], stored)
        self.assertEqual(photos["floor"].lens["name"], "stored")
        self.assertEqual(photos["chart"].lens["name"], "lab")
        # Without a stored placement the floor takes the lab's too; two of the photograph's size: neither (pinhole).
        self.assertEqual(self.build([self.calibration("lab")], None)["floor"].lens["name"], "lab")
        both = self.build([self.calibration("lab"), self.calibration("lab 2")], None)
        self.assertIsNone(both["chart"].lens)
        self.assertIsNone(both["floor"].lens)
        # A verification placed as a pinhole and a lab without calibrations: pinhole, said so in the caption.
        photos = self.build([], {"light": {"model": "pinhole", "lens": None, "how": "…"}})
        self.assertIsNone(photos["floor"].lens)
        self.assertIn("pinhole", overlay.floor_placement(photos["floor"]).how)
        # Compared as a pinhole (a daemon without the route then) in a lab that has a calibration now: the floor map is
        # drawn as it was compared, not through the lab's lens; the chart still takes the lab's.
        photos = self.build([self.calibration("lab")], {"light": {"model": "pinhole", "lens": None, "how": "…"}})
        self.assertIsNone(photos["floor"].lens)
        self.assertEqual(photos["chart"].lens["name"], "lab")


if __name__ == "__main__":
    unittest.main()
