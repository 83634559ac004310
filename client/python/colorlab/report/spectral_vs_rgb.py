"""Chapter 8's question with numbers: what a renderer that multiplies colour triples gets wrong against one that
multiplies spectra, patch by patch, under each of the cabinet's lamps.

Three renderers of one diffuse patch lit by one lamp, all on the chart-read's wavelength grid (box bands: a band's
value held over its width, as docs/verify.md's ``to_xyz``):

- **spectral** (the reference): XYZ = K Σ ρ(λ) S(λ) x̄ȳz̄(λ) Δλ, K putting the lamp's perfect diffuser at Y = 100.
- **RGB** (linear sRGB, what most renderers do, §8.1.1): the patch becomes its linear sRGB albedo — its colour under
  D65 (sRGB's white) through the IEC 61966-2-1 matrix, divided channel by channel by the perfect diffuser's so that
  white is (1, 1, 1) as a texture author makes it — and the lamp its linear sRGB triple; the renderer multiplies
  them component-wise and the result goes back to XYZ through the inverse matrix.
- **XYZ** (§8.1.2, the chapter's subject): the patch's XYZ under the equal-energy light, perfect diffuser
  (1, 1, 1), times the lamp's XYZ component-wise. §8.2: the product can leave the gamut of real colours; the
  chromaticity is tested against the spectral locus (and its purple line).

Each renderer's white is the lamp's own XYZ exactly (ρ = 1 gives the lamp's triple back), so the ΔE00 against the
spectral result (L*a*b* relative to the lamp's white, CIEDE2000) is the error of the multiplication alone, not of
a white point. Pure numpy; the CIE tables come from Debian's colord-data, as the analysis library reads them.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .tradeoff import delta_e00

# The cabinet's lamps and the CIE tables their spectra are (docs/verify.md "The measured scene").
LAMPS = (("D65", "D65"), ("TL84", "F11"), ("CWF", "F2"), ("A", "A"))

SRGB_PRIMARIES = ((0.64, 0.33), (0.30, 0.60), (0.15, 0.06))
SRGB_WHITE = (0.3127, 0.3290)


def colord_dir() -> Path:
    return Path(os.environ.get("COLORLAB_COLORD_DIR") or "/usr/share/colord")


def read_colord(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """colord's CGATS-like spectral file: (wavelengths, rows × bands)."""
    text = Path(path).read_text(encoding="utf-8")
    head = dict(line.split(None, 1) for line in text.splitlines()
                if line.startswith(("SPECTRAL_START_NM", "SPECTRAL_END_NM", "SPECTRAL_BANDS")))
    start, end, bands = float(head["SPECTRAL_START_NM"]), float(head["SPECTRAL_END_NM"]), int(head["SPECTRAL_BANDS"])
    body = text.split("BEGIN_DATA\n", 1)[1].split("END_DATA", 1)[0]
    rows = np.array([[float(v) for v in line.split()] for line in body.splitlines() if line.strip()])
    if rows.shape[1] != bands:
        raise ValueError(f"{path}: {rows.shape[1]} values per row, the header says {bands}")
    return np.linspace(start, end, bands), rows


def cmf(wavelengths) -> np.ndarray:
    """CIE 1931 2° x̄, ȳ, z̄ at the given wavelengths (bands × 3), linear between the table's 5 nm samples."""
    wl, rows = read_colord(colord_dir() / "cmf" / "CIE1931-2deg-XYZ.cmf")
    return np.stack([np.interp(wavelengths, wl, r, left=0.0, right=0.0) for r in rows], axis=1)


def lamp(cie: str, wavelengths) -> np.ndarray:
    wl, rows = read_colord(colord_dir() / "illuminant" / f"CIE-{cie}.sp")
    return np.interp(wavelengths, wl, rows[0], left=0.0, right=0.0)


def srgb_matrix() -> np.ndarray:
    """Linear sRGB → XYZ (white Y = 1) from the primaries and D65 (IEC 61966-2-1 §5.2's derivation)."""
    xyz = lambda x, y: np.array([x / y, 1.0, (1 - x - y) / y])  # noqa: E731
    prim = np.column_stack([xyz(*p) for p in SRGB_PRIMARIES])
    return prim * np.linalg.solve(prim, xyz(*SRGB_WHITE))


def xyz_to_lab(xyz, white) -> np.ndarray:
    t = np.asarray(xyz, float) / np.asarray(white, float)
    eps = (6 / 29) ** 3
    f = np.where(t > eps, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack([116 * f[:, 1] - 16, 500 * (f[:, 0] - f[:, 1]), 200 * (f[:, 1] - f[:, 2])], axis=1)


def _inside(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon (ray cast along +x)."""
    x, y = points[:, 0:1], points[:, 1:2]
    x0, y0 = polygon[:, 0], polygon[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    crosses = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        at = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    return (np.sum(crosses & (x < at), axis=1) % 2) == 1


def spectral_locus() -> np.ndarray:
    """The chromaticities of monochromatic light, 380-700 nm (beyond, x̄ȳz̄ are too small to add a point that
    is not on the same place), closed by the purple line."""
    wl, rows = read_colord(colord_dir() / "cmf" / "CIE1931-2deg-XYZ.cmf")
    keep = (wl >= 380) & (wl <= 700)
    c = rows[:, keep].T
    return c[:, :2] / c.sum(axis=1, keepdims=True)


def compare(wavelengths, reflectances, lamp_spd, observer=None) -> dict:
    """One lamp, N patches (reflectances N × bands on ``wavelengths``): each renderer's XYZ and its ΔE00 against
    the spectral one, and whether the XYZ renderer's products are real colours."""
    wl = np.asarray(wavelengths, float)
    r = np.asarray(reflectances, float)
    s = np.asarray(lamp_spd, float)
    o = cmf(wl) if observer is None else np.asarray(observer, float)
    step = np.gradient(wl) if len(wl) > 1 else np.ones(1)
    k = 100.0 / np.sum(s * o[:, 1] * step)
    white = k * (s * step) @ o                                      # the lamp's perfect diffuser, Y = 100
    spectral = k * (r * s * step) @ o

    m = srgb_matrix()
    d65 = lamp("D65", wl)
    under_d65 = (r * d65 * step) @ o
    albedo = np.linalg.solve(m, under_d65.T).T / np.linalg.solve(m, (d65 * step) @ o)
    light_rgb = np.linalg.solve(m, white)
    rgb = (albedo * light_rgb) @ m.T

    xyz_albedo = (r * step) @ o / (step @ o)
    xyz = xyz_albedo * white

    lab_ref = xyz_to_lab(spectral, white)
    chroma = xyz[:, :2] / np.maximum(xyz.sum(axis=1, keepdims=True), 1e-300)
    return {"white": white, "spectral": spectral, "rgb": rgb, "xyz": xyz,
            "rgb_de00": delta_e00(xyz_to_lab(rgb, white), lab_ref),
            "xyz_de00": delta_e00(xyz_to_lab(xyz, white), lab_ref),
            "albedo_out_of_gamut": np.any(albedo < 0, axis=1) | np.any(albedo > 1, axis=1),
            "xyz_invalid": ~_inside(chroma, spectral_locus())}


def by_lamp(wavelengths, reflectances) -> dict:
    """compare() under each of the cabinet's lamps: {lamp name: result}."""
    return {name: compare(wavelengths, reflectances, lamp(cie, wavelengths)) for name, cie in LAMPS}
