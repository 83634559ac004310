"""The photographs a verification was checked against, for its maps over the photograph (docs/verify.md "Report"):
the characterize-camera run's chart photograph with the located chart's corners, and the floor-luminance run's
floor photograph with the floor's corners — each the run's kept frame as the daemon previews it (the kept PNG, or
``GET /v1/blobs/{sha}/preview.png`` of the averaged mosaic), reduced to grey and downscaled.

Positions stay in the photograph's own pixels (pixel centres at integers, as the locator and the floor homography
give them); the downscaled image is placed over them by its extent, so nothing here moves a patch.
"""
from __future__ import annotations

import io
from dataclasses import dataclass, field

import numpy as np
from matplotlib import image as mpimg

# The floor the floor-luminance campaign maps (its default floor_mm; docs/campaigns.md), corners front-left,
# front-right, back-right, back-left — the order of the photograph row's corners_px.
FLOOR_MM = (1200.0, 600.0)
MAX_WIDTH_PX = 900  # the report's image: enough to see the chart's patches, small enough to inline


@dataclass
class Photo:
    grey: np.ndarray            # downscaled, 0..1
    width: int                  # the photograph's own size, pixels
    height: int
    corners: np.ndarray         # 4 × 2, photograph pixels
    run_id: str
    blob: str                   # sha256 of the kept frame shown
    what: str = ""              # "chart/raw" or "P/D65/D100"
    extra: dict = field(default_factory=dict)
    lens: dict | None = None    # the lens it was taken through (verification_lens.lens_dict), None: placed as a pinhole


def homography(src, dst) -> np.ndarray:
    """The 3 × 3 projective map taking four points src to dst (direct linear transform, h33 = 1)."""
    a, b = [], []
    for (x, y), (u, v) in zip(np.asarray(src, float), np.asarray(dst, float)):
        a.append([x, y, 1, 0, 0, 0, -u * x, -u * y]), b.append(u)
        a.append([0, 0, 0, x, y, 1, -v * x, -v * y]), b.append(v)
    h = np.linalg.solve(np.array(a), np.array(b))
    return np.append(h, 1.0).reshape(3, 3)


def apply(h: np.ndarray, pts) -> np.ndarray:
    p = np.asarray(pts, float).reshape(-1, 2)
    q = np.c_[p, np.ones(len(p))] @ h.T
    return q[:, :2] / q[:, 2:3]


def grey_of(png: bytes, max_width: int = MAX_WIDTH_PX) -> np.ndarray:
    """A PNG as grey 0..1 (the channels' mean: the false colour over it must not be confused with the scene's),
    block-averaged down to at most max_width pixels wide."""
    img = mpimg.imread(io.BytesIO(png), format="png")
    if img.dtype.kind in "ui":  # matplotlib gives floats 0..1 for PNG; an integer array is scaled the same way
        img = img / np.iinfo(img.dtype).max
    img = np.asarray(img, dtype=float)
    grey = img[..., :3].mean(axis=2) if img.ndim == 3 else img
    k = max(1, int(np.ceil(grey.shape[1] / max_width)))
    h, w = grey.shape[0] // k * k, grey.shape[1] // k * k
    return grey[:h, :w].reshape(h // k, k, w // k, k).mean(axis=(1, 3))


def _rows(client, run_id, prefix):
    return list(client.measurement_items(run_id, step_prefix=prefix))


def _blob_png(client, item) -> bytes:
    if item.get("media_type") == "image/png":
        return client.read_blob(item["sha256"])
    return client.preview(item["sha256"])


def _kept(client, run_id, call):
    """The run's kept frames of one camera call kind, grouped per call in journal order: [[items of call 0], …]."""
    groups = {}
    for item in client.blobs(run_id).to_dict("records"):
        name = str(item.get("name", ""))
        head = name.split("/", 1)[0]
        if head.split("#", 1)[0] != call:
            continue
        try:
            seq = int(head.split("#", 1)[1])
        except (IndexError, ValueError):
            seq = 0
        groups.setdefault(seq, []).append(item)
    return [groups[k] for k in sorted(groups)]


def _best(items):
    """The frame to show: the kept preview, else the averaged mosaic, else the raw file (previewed by the daemon)."""
    for kind in ("preview", "average", "raw"):
        for it in items:
            if it.get("kind") == kind:
                return it
    return None


def chart_photo(client, run_id) -> Photo | None:
    """A characterize-camera run's raw chart photograph and the locator's corners (A1's, N1's, N10's, A10's outer
    corner, photograph pixels)."""
    rows = [r for r in _rows(client, run_id, "chart/") if r.get("step") == "chart/raw"]
    data = (rows[0].get("data") or {}) if rows else {}
    corners = data.get("corners")
    if not corners or len(corners) != 4 or not data.get("width") or not data.get("height"):
        return None
    calls = _kept(client, run_id, "camera.photograph_chart")
    item = _best(calls[-1]) if calls else None
    if item is None:
        return None
    return Photo(grey_of(_blob_png(client, item)), int(data["width"]), int(data["height"]),
                 np.asarray(corners, float), run_id, item["sha256"], "chart/raw")


def _floor_row(rows, floor_items):
    """The P/<lamp>/D<level> row whose F/ cells are the values the verification compared (its light_floor
    'measured'), else the first (the CLI's default lamp and level)."""
    photos = [r for r in rows if str(r.get("step", "")).startswith("P/")]
    if not photos:
        return None
    measured = {c["where"]: (c.get("measured") or [None])[0] for c in floor_items}
    for p in photos:
        level = str(p["step"])[2:]
        cells = {str(r["step"])[len(level) + 3:]: r.get("value") for r in rows
                 if str(r.get("step", "")).startswith(f"F/{level}/")}
        if measured and all(w in cells and v is not None and cells[w] is not None
                            and abs(cells[w] - v) <= 1e-9 * max(1.0, abs(v)) for w, v in measured.items()):
            return p
    return photos[0]


def floor_photo(client, run_id, floor_items) -> Photo | None:
    """A floor-luminance run's floor photograph for the lamp and level compared, with the floor's corners."""
    rows = _rows(client, run_id, None)
    row = _floor_row(rows, floor_items)
    if row is None:
        return None
    data = row.get("data") or {}
    corners = data.get("corners_px")
    if not corners or len(corners) != 4 or not data.get("width") or not data.get("height"):
        return None
    level = str(row["step"])[2:]  # "<lamp>/D<level>"
    lamp, _, dimmer = level.partition("/D")
    calls = _kept(client, run_id, "camera.photograph_floor")
    # A kept frame's step is the run's progress label when it was committed: floor-luminance labels each level
    # "<lamp> <level>%" before photographing it. The last frame under this level's label (a lamp change retakes the
    # level); else, when every level was photographed once, the level's place among the P rows.
    tags = (f"{lamp} {dimmer}%", f"P/{level}", f"C/{level}/")
    tagged = [c for c in calls if any(str(it.get("step", "")).startswith(tags) for it in c)]
    ps = [r for r in rows if str(r.get("step", "")).startswith("P/")]
    if tagged:
        chosen = tagged[-1]
    elif len(calls) == len(ps):
        chosen = calls[ps.index(row)]
    else:
        return None
    item = _best(chosen)
    if item is None:
        return None
    return Photo(grey_of(_blob_png(client, item)), int(data["width"]), int(data["height"]),
                 np.asarray(corners, float), run_id, item["sha256"], str(row["step"]),
                 {"spot_mm": float(data.get("spot_mm") or 20.0)})


def load(client, run, items_by_kind) -> dict:
    """{"chart": Photo, "floor": Photo} for the runs the verification names in ``against`` (each missing when the
    run, its geometry or its kept frame is not there). A photograph that cannot be had leaves its map out; it never
    stops the report."""
    from . import verification_lens as lenses  # it builds on this module's homography

    out = {}
    if client is None:
        return out
    params = run.doc.get("params") or {}
    against = [str(a) for a in params.get("against") or []]
    light = (params.get("placement") or {}).get("light") or {}
    stored_lens = light.get("lens") if light.get("model") == "lens calibration" else None
    # Compared as a pinhole (no calibration then, or a daemon without the route): drawn as compared, not through a
    # lens the comparison never used.
    stored_pinhole = light.get("model") == "pinhole"
    calibrations = None

    def lens_for(photo, stored=None):
        nonlocal calibrations
        if calibrations is None:
            try:
                calibrations = client.lenses().to_dict("records")
            except Exception:  # noqa: BLE001 — a daemon without the route, a fake: the photograph as a pinhole
                calibrations = []
        lens = lenses.choose(photo.width, photo.height, stored, calibrations)
        try:
            lenses.undistort(lens, photo.corners)
        except ValueError:  # corners the lens cannot take (not this photograph's lens): placed as a pinhole
            return None
        return lens

    for rid in against:
        try:
            doc = dict(client.run(rid))
            kind = doc.get("campaign")
            # The overlay's patch grid is the SG's (verification_overlay.SG_COLUMNS × SG_ROWS): a ColorChecker 24
            # run gets no map over its photograph rather than squares in the wrong places.
            chart = str((doc.get("params") or {}).get("chart", "sg"))
            if kind == "characterize-camera" and chart == "sg" and "chart" not in out and (
                    "colour_7_3" in items_by_kind or "colour_7_4" in items_by_kind):
                photo = chart_photo(client, rid)
                if photo is not None:
                    photo.lens = lens_for(photo)
                    out["chart"] = photo
            elif kind == "floor-luminance" and "floor" not in out and (
                    "light_floor" in items_by_kind or "light_spot" in items_by_kind):
                photo = floor_photo(client, rid, items_by_kind.get("light_floor", []))
                if photo is not None:
                    photo.lens = None if stored_pinhole else lens_for(photo, stored_lens)
                    out["floor"] = photo
        except Exception:  # noqa: BLE001 — the maps on the chart's and floor's own coordinates still stand
            continue
    return out
