"""Placing a plane (the chart's patch grid, the cabinet floor) on a photograph through the lab's lens calibration
(docs/verify.md "Report"): the photograph is distorted (OpenCV's radial k1, k2), a plane's pinhole image is a
homography. So the four measured corners are undistorted, the homography is taken between the plane and those
pinhole positions, and every point placed is distorted back into the photograph — what a pinhole homography of the
distorted corners gets wrong by pixels towards the frame's edges. Without a lens: the pinhole homography, as before.

The lens is the one the verification stored (``params.placement.light.lens``: what ``colorlab verify`` placed the
floor through), else the daemon's calibration for the photograph's size (``Client.lenses()``, one of that size).
"""
from __future__ import annotations

import numpy as np

from .verification_photo import apply, homography

LENS_KEYS = ("fx", "fy", "cx", "cy", "k1", "k2")


def lens_dict(item) -> dict | None:
    """{fx, fy, cx, cy, k1, k2, name} from a calibration row or a stored placement's lens; None when incomplete."""
    try:
        lens = {k: float(item.get(k) or 0.0) if k in ("k1", "k2") else float(item[k]) for k in LENS_KEYS}
    except (KeyError, TypeError, ValueError):
        return None
    if not (lens["fx"] > 0 and lens["fy"] > 0) or not all(np.isfinite(list(lens.values()))):
        return None
    lens["name"] = str(item.get("name") or "")
    return lens


def distort(lens, pts) -> np.ndarray:
    """Pinhole pixel positions → the photograph's (cv::projectPoints' radial model)."""
    p = np.asarray(pts, float).reshape(-1, 2)
    if not lens:
        return p
    x, y = (p[:, 0] - lens["cx"]) / lens["fx"], (p[:, 1] - lens["cy"]) / lens["fy"]
    r2 = x * x + y * y
    k = 1 + lens["k1"] * r2 + lens["k2"] * r2 * r2
    return np.c_[lens["cx"] + lens["fx"] * x * k, lens["cy"] + lens["fy"] * y * k]


def undistort(lens, pts) -> np.ndarray:
    """The photograph's pixel positions → the pinhole's: r (1 + k1 r² + k2 r⁴) = r_d solved for r by Newton's
    method. ValueError for a point beyond where the model is one-to-one (no pinhole position)."""
    p = np.asarray(pts, float).reshape(-1, 2)
    if not lens or (lens["k1"] == 0 and lens["k2"] == 0):
        return p
    xd, yd = (p[:, 0] - lens["cx"]) / lens["fx"], (p[:, 1] - lens["cy"]) / lens["fy"]
    rd = np.hypot(xd, yd)
    r = rd.copy()
    for _ in range(50):
        r2 = r * r
        d = 1 + 3 * lens["k1"] * r2 + 5 * lens["k2"] * r2 * r2
        if np.any(d <= 0):
            raise ValueError("a corner lies beyond where the lens model is one-to-one")
        r = r - (r * (1 + lens["k1"] * r2 + lens["k2"] * r2 * r2) - rd) / d
    r2 = r * r
    if np.any(np.abs(r * (1 + lens["k1"] * r2 + lens["k2"] * r2 * r2) - rd) > 1e-12 * (1 + rd)):
        raise ValueError("the lens model did not invert at a corner")
    s = np.divide(r, rd, out=np.ones_like(rd), where=rd > 0)
    return np.c_[lens["cx"] + lens["fx"] * xd * s, lens["cy"] + lens["fy"] * yd * s]


class Placement:
    """Plane coordinates → photograph pixels from the plane's four corners (``plane``, in order) as photographed
    (``corners_px``), through ``lens`` when given."""

    def __init__(self, plane, corners_px, lens=None):
        self.lens = lens
        self.h = homography(plane, undistort(lens, corners_px))

    @property
    def how(self) -> str:
        if not self.lens:
            return "pinhole (no lens calibration for this photograph)"
        return f"through the lens calibration {self.lens['name']}" if self.lens["name"] else "through the lens calibration"

    def __call__(self, pts) -> np.ndarray:
        return distort(self.lens, apply(self.h, pts))

    def polygon(self, pts, steps: int = 8) -> np.ndarray:
        """A plane polygon's outline in the photograph, each edge cut into ``steps`` so that it bends as the lens
        bends it."""
        p = np.asarray(pts, float).reshape(-1, 2)
        if not self.lens:
            return self(p)
        t = np.arange(steps)[:, None] / steps
        edges = [a + t * (b - a) for a, b in zip(p, np.roll(p, -1, axis=0))]
        return self(np.vstack(edges))


def choose(photo_width, photo_height, stored=None, calibrations=None) -> dict | None:
    """The lens for a photograph: the stored placement's when it holds for this size, else the only calibration of
    this size among ``calibrations`` (rows of ``Client.lenses()``), else None (pinhole)."""
    if stored:
        lens = lens_dict(stored)
        w, h = stored.get("width_px"), stored.get("height_px")
        if lens and (w is None or (int(w), int(h)) == (int(photo_width), int(photo_height))):
            return lens
    fit = [c for c in (calibrations or [])
           if int(c.get("width_px") or 0) == int(photo_width) and int(c.get("height_px") or 0) == int(photo_height)]
    return lens_dict(fit[0]) if len(fit) == 1 else None
