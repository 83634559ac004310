"""The colour arithmetic chapter 7's tables need, in numpy: Adobe RGB (1998) → CIE L*a*b* (D50), ΔE*ab, the
dissertation's eleven polynomials (§7.3, eqs. 1-2) and the five statistics its tables give."""
from __future__ import annotations

import re

import numpy as np

D50 = np.array([0.9642, 1.0, 0.8249])
BRADFORD = np.array([[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367], [0.0389, -0.0685, 1.0296]])


def rgb_to_xyz_d50(primaries_xy, white_xy) -> np.ndarray:
    """An RGB space's matrix to XYZ, adapted to D50 by Bradford: what lcms (and so the daemon) builds from the
    space's primaries and white, so the report's numbers and the daemon's agree to its precision."""
    xyz = lambda x, y: np.array([x / y, 1.0, (1 - x - y) / y])  # noqa: E731
    prim = np.column_stack([xyz(*p) for p in primaries_xy])
    white = xyz(*white_xy)
    m = prim * np.linalg.solve(prim, white)
    cone = np.diag((BRADFORD @ D50) / (BRADFORD @ white))
    return np.linalg.solve(BRADFORD, cone @ BRADFORD) @ m


# Adobe RGB (1998): D65 white, its primaries, pure gamma 563/256 (analysis/src/rgb_spaces.cpp builds the same).
ADOBE_D50 = rgb_to_xyz_d50([(0.64, 0.33), (0.21, 0.71), (0.15, 0.06)], (0.3127, 0.3290))
ADOBE_GAMMA = 563 / 256


def xyz_to_lab(xyz: np.ndarray, white: np.ndarray = D50) -> np.ndarray:
    t = np.asarray(xyz, float) / white
    eps = (6 / 29) ** 3
    f = np.where(t > eps, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack([116 * f[:, 1] - 16, 500 * (f[:, 0] - f[:, 1]), 200 * (f[:, 1] - f[:, 2])], axis=1)


def adobe_rgb_to_lab(rgb01: np.ndarray) -> np.ndarray:
    """§7.1: the camera's encoded values read as Adobe RGB, nothing fitted."""
    lin = np.clip(np.asarray(rgb01, float), 0, None) ** ADOBE_GAMMA
    return xyz_to_lab(lin @ ADOBE_D50.T)


def delta_e76(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.asarray(a, float) - np.asarray(b, float), axis=1)


def stats(values) -> dict:
    """The five rows of Tables 9-13. Stdev with n - 1, as the window standard deviations of §6.2."""
    v = np.asarray(values, float)
    return {"Min": float(v.min()), "Max": float(v.max()), "Median": float(np.median(v)), "Mean": float(v.mean()),
            "Stdev": float(v.std(ddof=1))}


# §7.3's polynomials 1-11 as printed (terms; "1" is the constant).
POLYNOMIALS = {
    1: "r g b",
    2: "r g b rgb 1",
    3: "r g b rg rb gb",
    4: "r g b rg rb gb rgb 1",
    5: "r g b rg rb gb r2 g2 b2",
    6: "r g b rg rb gb r2 g2 b2 rgb 1",
    7: "r g b rg rb gb r2 g2 b2 r3 g3 b3 1",
    8: "r g b rg rb gb r2 g2 b2 r2g2 r2b2 g2b2 r2g2b2 r3 g3 b3 r3g3 r3b3 g3b3 1",
    9: "r g b rg rb gb r2 g2 b2 r3 g3 b3 r4 g4 b4 1",
    10: "r g b rg rb gb rgb r2 g2 b2 r2g2 r2b2 g2b2 r2g2b2 r3 g3 b3 r3g3 r3b3 g3b3 r3g3b3 r4 g4 b4 r4g4 r4b4 g4b4 r4g4b4 1",
    11: "r g b rg rb gb r2 g2 b2 r3 g3 b3 r4 g4 b4 r5 g5 b5 1",
}


def _exponents(term: str):
    if term == "1":
        return (0, 0, 0)
    e = {"r": 0, "g": 0, "b": 0}
    for ch, power in re.findall(r"([rgb])(\d*)", term):
        e[ch] = int(power or 1)
    return (e["r"], e["g"], e["b"])


def design(rgb01: np.ndarray, polynomial: int) -> np.ndarray:
    x = np.asarray(rgb01, float)
    cols = [x[:, 0] ** p * x[:, 1] ** q * x[:, 2] ** s for p, q, s in map(_exponents, POLYNOMIALS[polynomial].split())]
    return np.stack(cols, axis=1)


def fit_polynomial(rgb01: np.ndarray, lab: np.ndarray, polynomial: int) -> np.ndarray:
    """Eq. (2), M = (RᵀR)⁻¹RᵀL, solved as least squares; returns the fitted L*a*b* of the training patches
    (the dissertation reports the training error: its tables fit and evaluate on the same 140 patches)."""
    r = design(rgb01, polynomial)
    m, *_ = np.linalg.lstsq(r, np.asarray(lab, float), rcond=None)
    return r @ m


def fit_matrix_shaper(rgb01: np.ndarray, xyz100: np.ndarray, gamma: float = 2.2) -> np.ndarray:
    """§7.2's profile as the lab builds it (analysis/src/icc_profile.cpp): a pure-gamma shaper, then a 3 × 3
    matrix to D50 XYZ by least squares; returns the training patches' L*a*b*. The run keeps neither the profile
    nor its per-patch errors, only its statistics, which this reproduces."""
    lin = np.clip(np.asarray(rgb01, float), 0, None) ** gamma
    m, *_ = np.linalg.lstsq(lin, np.asarray(xyz100, float) / 100.0, rcond=None)
    return xyz_to_lab(lin @ m)
