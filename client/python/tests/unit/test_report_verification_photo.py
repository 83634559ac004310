"""The verification's maps over the photograph (docs/verify.md "Report"), without a daemon.

A fake client serves what colorlabd serves for the runs a verification names in ``against``: a characterize-camera
run (its ``chart/raw`` row with the locator's corners, its kept preview PNG at half the photograph's size, as the
daemon keeps one) and a floor-luminance run (``P/…`` rows with the floor's ``corners_px``, ``F/…`` cells, a kept
preview per level). The truth is this test's own: a pinhole camera it poses in 3-D in front of the chart and the
floor. The corners it hands the report are that camera's projection of the grid's and floor's corners, and where a
patch or a floor cell must appear is the same camera's projection of its centre — not the report's homography.

Checks, on the figure rasterised: the planted defect patch (3.1 ΔE00) shows, at its own projected centre, the
colour its value has on the figure's colour scale, and its neighbours show theirs; the defect is outlined red; a
white marker painted into the photograph shows at its own place (the photograph is placed by its extent, the half-
size preview mapped back to full-size pixels); the floor's 10 % brighter region (rows 0–2 × cols 0–3) reads 1.10 ±
0.01 in the translucent ratio layer once the known photograph is taken out of the blend, a cell outside it 1.00 ±
0.01; of two floor levels, the one whose cells the verification compared is the one shown.
"""
from __future__ import annotations

import io
import unittest

import numpy as np
import pandas as pd
from matplotlib import image as mpimg

from colorlab.report import verification
from colorlab.report import verification_overlay as overlay
from colorlab.report.fetch import RunData
from colorlab.tables import measurements_frame

W, H = 1600, 1200  # the photograph's full size; its kept preview is half that (the daemon's mosaic preview)
PITCH_MM = 19.0
SIDE = 15.0 / 19.0  # an SG's patch side in pitches: 15 mm patches on a 19 mm pitch
DEFECT_PATCH = "F5"
DEFECT_RATIO = 1.10


def look_at(eye, target, f, cx, cy):
    """Project world points (mm) through a pinhole at eye looking at target, image y downwards."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0]) if abs(z[2]) < 0.99 else np.array([1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)

    def project(p):
        d = np.asarray(p, float) - eye
        return np.array([cx + f * d @ x / (d @ z), cy + f * d @ y / (d @ z)])
    return project


# The chart lies in the plane z = 0, grid unit g → (g_x, −g_y)·pitch (A1 top left); the camera leans over it.
CHART_CAM = look_at([140.0, -420.0, 560.0], [140.0, -98.0, 0.0], 1500.0, W / 2 - 0.5, H / 2 - 0.5)


def chart_px(gx, gy):
    return CHART_CAM([gx * PITCH_MM, -gy * PITCH_MM, 0.0])


# The floor: x from the left wall, y from the front, the camera above and before the open front.
FLOOR_CAM = look_at([600.0, -900.0, 800.0], [600.0, 300.0, 0.0], 900.0, W / 2 - 0.5, H / 2 - 0.5)


def floor_px(x_mm, y_mm):
    return FLOOR_CAM([x_mm, y_mm, 0.0])


def png(grey: np.ndarray) -> bytes:
    buf = io.BytesIO()
    mpimg.imsave(buf, np.dstack([grey] * 3), vmin=0, vmax=1, format="png")
    return buf.getvalue()


def patch_ids():
    return [f"{c}{r}" for c in "ABCDEFGHIJKLMN" for r in range(1, 11)]


def comparison(kind, where, difference, differs, cannot_tell=False, measured=None):
    return {"kind": kind, "where": where, "rendered": [0.0], "measured": [measured if measured is not None else 1.0],
            "difference": difference, "expanded": 1.0, "mahalanobis": 1.0, "threshold": 2.0,
            "verdict": "differs" if differs else "agrees", "cannot_tell": cannot_tell, "budget": {}}


class FakeClient:
    """GET /v1/runs/{id}, its measurements, its blobs, and blob bytes, as colorlab.Client gives them."""

    def __init__(self):
        self.docs, self.rows, self.kept, self.bytes = {}, {}, {}, {}

    def run(self, rid):
        return self.docs[rid]

    def measurement_items(self, rid, step_prefix=None, **_):
        return [m for m in self.rows[rid] if step_prefix is None or m["step"].startswith(step_prefix)]

    def blobs(self, rid):
        return pd.DataFrame(self.kept[rid])

    def read_blob(self, sha):
        return self.bytes[sha]

    def preview(self, sha):
        return self.bytes[sha]


def measurement(i, step, value, data):
    return {"seq": i, "step": step, "instrument_id": "x", "quantity": "q", "value": value, "unit": "",
            "measured_at": "2026-11-29T06:00:00Z", "simulated": True, "data": data}


def build():
    rng = np.random.default_rng(23)
    client = FakeClient()
    # The chart photograph: dark grey, a white marker square at a known place away from the chart.
    photo = np.full((H, W), 0.25)
    photo[40:120, 60:140] = 1.0
    client.docs["cc"] = {"id": "cc", "campaign": "characterize-camera"}
    gw, gh = 13 + SIDE, 9 + SIDE
    corners = [list(chart_px(x, y)) for x, y in ((0, 0), (gw, 0), (gw, gh), (0, gh))]
    client.rows["cc"] = [measurement(1, "chart/raw", 1.0, {"format": "raw", "corners": corners, "width": W,
                                                          "height": H, "reprojection_rms_px": 0.1})]
    half = photo.reshape(H // 2, 2, W // 2, 2).mean(axis=(1, 3))
    client.bytes["a" * 64] = png(half)
    client.kept["cc"] = [{"name": "camera.photograph_chart#3/preview", "sha256": "a" * 64, "kind": "preview",
                          "step": "chart/raw", "media_type": "image/png"}]
    # The floor: two levels photographed; the verification compared D65 at 50 %.
    client.docs["fl"] = {"id": "fl", "campaign": "floor-luminance"}
    floor_corners = [list(floor_px(x, y)) for x, y in ((0, 0), (1200, 0), (1200, 600), (0, 600))]
    rows, i = [], 1
    cells = {}
    for level in ("D100", "D50"):
        rows.append(measurement(i, f"P/D65/{level}", 1.0, {"width": W, "height": H, "corners_px": floor_corners,
                                                            "spot_mm": 20}))
        i += 1
        for r in range(8):
            for c in range(10):
                v = float(rng.uniform(100, 300))
                cells[(level, r, c)] = v
                rows.append(measurement(i, f"F/D65/{level}/r{r}c{c}", v, {"row": r, "col": c}))
                i += 1
    client.rows["fl"] = rows
    client.bytes["b" * 64] = png(np.full((H // 2, W // 2), 0.1))  # D100's frame: darker, must not be shown
    client.bytes["c" * 64] = png(np.full((H // 2, W // 2), 0.6))
    # Kept frames carry the run's progress label as their step, as colorlabd commits them.
    client.kept["fl"] = [{"name": "camera.photograph_floor#2/preview", "sha256": "b" * 64, "kind": "preview",
                          "step": "D65 100%", "media_type": "image/png"},
                         {"name": "camera.photograph_floor#40/preview", "sha256": "c" * 64, "kind": "preview",
                          "step": "D65 50%", "media_type": "image/png"}]
    # The verification: every patch, one 3.1 ΔE00 off; the floor map at D65 50 %, rows 0–2 × cols 0–3 10 % bright.
    comps = []
    values = {}
    for pid in patch_ids():
        d = 3.1 if pid == DEFECT_PATCH else float(rng.uniform(0.0, 0.8))
        values[pid] = d
        comps.append(comparison("colour_7_3", pid, d, pid == DEFECT_PATCH, cannot_tell=pid == "A1"))
    for r in range(8):
        for c in range(10):
            bright = r <= 2 and c <= 3
            d = DEFECT_RATIO - 1 if bright else float(rng.uniform(-0.005, 0.005))
            m = cells[("D50", r, c)]
            comps.append(comparison("light_floor", f"r{r}c{c}", d, bright, measured=m))
    items = [measurement(k + 1, f"{x['kind']}/{x['where']}", x["difference"], x) for k, x in enumerate(comps)]
    doc = {"id": "01a20a70-bc32-7d8d-bc85-0000000000f2", "campaign": "verify", "status": "finished_ok",
           "params": {"rendering": "box.exr", "against": ["cc", "fl"], "scale": 1.0, "k": 2}, "summary": {}}
    run = RunData(doc, measurements_frame(items))
    verification.link(client, [run])
    return run, values


def raster(fig, dpi=200):
    fig.set_dpi(dpi)
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(float) / 255.0


def pixel(img, ax, xy):
    """The raster's colour at photograph pixel xy (display y runs upwards)."""
    dx, dy = ax.transData.transform(xy)
    return img[int(round(img.shape[0] - dy)), int(round(dx))]


def value_of(rgb, cmap, norm):
    lut = cmap(np.linspace(0, 1, 1024))[:, :3]
    k = int(np.argmin(((lut - rgb) ** 2).sum(axis=1)))
    return float(norm.inverse(k / 1023)), float(np.sqrt(((lut[k] - rgb) ** 2).sum()))


class MapsOverThePhotograph(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.vrun, cls.values = build()
        cls.photos = cls.vrun.extra["photos"]
        from colorlab.report import verification_data as vd
        cls.kinds = vd.by_kind(vd.comparisons(cls.vrun))

    def test_both_photographs_found(self):
        self.assertEqual(set(self.photos), {"chart", "floor"})
        self.assertEqual(self.photos["floor"].what, "P/D65/D50")
        html = verification.section(self.vrun)
        for fid in ("fig-verify-chart-photo", "fig-verify-floor-photo"):
            self.assertIn(f'id="r0000000000f2-{fid}"', html)

    def test_defect_patch_at_its_place_in_its_colour(self):
        fig, panels = overlay.chart_figure(self.photos["chart"], self.kinds)
        (ax, kind, cmap, norm), = panels
        img = raster(fig)
        for pid in (DEFECT_PATCH, "E5", "G5", "F4", "F6", "N10"):
            col, row = ord(pid[0]) - ord("A"), int(pid[1:]) - 1
            centre = chart_px(col + SIDE / 2, row + SIDE / 2)  # the test's own camera, not the report's homography
            want = np.array(cmap(norm(self.values[pid]))[:3])
            got = pixel(img, ax, centre)
            self.assertLess(np.abs(got - want).max(), 3 / 255, (pid, got, want))
        v, dist = value_of(pixel(img, ax, chart_px(5 + SIDE / 2, 4 + SIDE / 2)), cmap, norm)
        self.assertAlmostEqual(v, 3.1, delta=0.02)
        # The red outline: on the defect patch's edge, half way along its top.
        edge = pixel(img, ax, chart_px(5 + SIDE / 2, 4.0))
        self.assertGreater(edge[0], 0.6)
        self.assertLess(edge[1], 0.35)

    def test_photograph_placed_by_its_extent(self):
        fig, panels = overlay.chart_figure(self.photos["chart"], self.kinds)
        ax = panels[0][0]
        img = raster(fig)
        self.assertGreater(pixel(img, ax, (99.5, 79.5)).min(), 0.95)  # the marker's centre, full-size pixels
        self.assertLess(pixel(img, ax, (99.5, 200.0)).max(), 0.35)    # below it, the dark photograph

    def test_floor_ratio_layer_reads_the_defect(self):
        fig, panels = overlay.floor_figure(self.photos["floor"], self.kinds)
        (ax, kind, cmap, norm), = panels
        img = raster(fig)
        under = pixel(img, ax, (W / 2, 15.0))  # the photograph above the floor's back edge: no layer over it
        self.assertAlmostEqual(float(under.mean()), 0.6, delta=3 / 255)  # the D50 frame, not D100's 0.1
        a = overlay.RATIO_ALPHA
        for (r, c), want in (((1, 1), DEFECT_RATIO), ((0, 3), DEFECT_RATIO), ((2, 0), DEFECT_RATIO),
                             ((5, 7), 1.0), ((3, 4), 1.0)):
            seen = pixel(img, ax, floor_px((c + 0.5) * 60, (r + 0.5) * 54))
            colour = (seen - (1 - a) * under) / a
            v, dist = value_of(np.clip(colour, 0, 1), cmap, norm)
            self.assertLess(dist, 0.03, (r, c))
            self.assertAlmostEqual(v, want, delta=0.01, msg=(r, c))


if __name__ == "__main__":
    unittest.main()
