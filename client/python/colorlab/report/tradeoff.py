"""The arithmetic of speed against accuracy (issue 11), with no HTML in it: Pareto fronts, the cheapest setting
that meets a rule, CIEDE2000, k-fold cross-validation and timed refits of §7.3's polynomials, in numpy.

Kept apart from the sections so the unit tests check it on synthetic data."""
from __future__ import annotations

import time

import numpy as np

from . import colour


def pareto_front(costs, errors) -> list[int]:
    """Indices of the points no other point dominates (cost ≤ and error ≤, one of them <), cheapest first.
    Equal points are all kept."""
    c, e = np.asarray(costs, float), np.asarray(errors, float)
    order = sorted(range(len(c)), key=lambda i: (c[i], e[i]))
    front, best = [], np.inf
    for i in order:
        if e[i] < best or (front and c[i] == c[front[-1]] and e[i] == e[front[-1]]):
            front.append(i)
            best = min(best, e[i])
    return front


def cheapest_meeting(costs, errors, limit: float):
    """Index of the cheapest point whose error is ≤ limit (ties on cost: the smaller error), None if none is."""
    ok = [i for i in range(len(costs)) if errors[i] <= limit]
    return min(ok, key=lambda i: (costs[i], errors[i])) if ok else None


# ---- CIEDE2000 (Sharma, Wu & Dalal 2005) ------------------------------------------------------------------------

def delta_e00(lab1, lab2) -> np.ndarray:
    a, b = np.atleast_2d(np.asarray(lab1, float)), np.atleast_2d(np.asarray(lab2, float))
    L1, a1, b1 = a.T
    L2, a2, b2 = b.T
    c1, c2 = np.hypot(a1, b1), np.hypot(a2, b2)
    cm = (c1 + c2) / 2
    g = 0.5 * (1 - np.sqrt(cm ** 7 / (cm ** 7 + 25.0 ** 7)))
    a1p, a2p = (1 + g) * a1, (1 + g) * a2
    c1p, c2p = np.hypot(a1p, b1), np.hypot(a2p, b2)
    h1p = np.degrees(np.arctan2(b1, a1p)) % 360
    h2p = np.degrees(np.arctan2(b2, a2p)) % 360
    dl, dc = L2 - L1, c2p - c1p
    dh = h2p - h1p
    dh = np.where(dh > 180, dh - 360, np.where(dh < -180, dh + 360, dh))
    dh = np.where(c1p * c2p == 0, 0.0, dh)
    dhh = 2 * np.sqrt(c1p * c2p) * np.sin(np.radians(dh / 2))
    lm, cmp_ = (L1 + L2) / 2, (c1p + c2p) / 2
    hs = h1p + h2p
    hm = np.where(c1p * c2p == 0, hs, np.where(np.abs(h1p - h2p) <= 180, hs / 2,
                                                 np.where(hs < 360, (hs + 360) / 2, (hs - 360) / 2)))
    t = (1 - 0.17 * np.cos(np.radians(hm - 30)) + 0.24 * np.cos(np.radians(2 * hm))
         + 0.32 * np.cos(np.radians(3 * hm + 6)) - 0.20 * np.cos(np.radians(4 * hm - 63)))
    sl = 1 + 0.015 * (lm - 50) ** 2 / np.sqrt(20 + (lm - 50) ** 2)
    sc = 1 + 0.045 * cmp_
    sh = 1 + 0.015 * cmp_ * t
    rt = (-2 * np.sqrt(cmp_ ** 7 / (cmp_ ** 7 + 25.0 ** 7))
          * np.sin(np.radians(60 * np.exp(-(((hm - 275) / 25) ** 2)))))
    return np.sqrt((dl / sl) ** 2 + (dc / sc) ** 2 + (dhh / sh) ** 2 + rt * (dc / sc) * (dhh / sh))


# ---- polynomials: fit, apply, cross-validate ---------------------------------------------------------------------

def fit(rgb01, lab, polynomial: int) -> np.ndarray:
    """Eq. (2)'s matrix, least squares (the design of colour.POLYNOMIALS)."""
    m, *_ = np.linalg.lstsq(colour.design(rgb01, polynomial), np.asarray(lab, float), rcond=None)
    return m


def apply(rgb01, m, polynomial: int) -> np.ndarray:
    return colour.design(rgb01, polynomial) @ m


def folds(n: int, k: int) -> list[np.ndarray]:
    """k folds by position (patch i in fold i mod k): deterministic, and a chart's neighbours fall apart."""
    idx = np.arange(n)
    return [idx[idx % k == f] for f in range(k)]


def cross_validated(rgb01, lab, polynomial: int, k: int = 10) -> np.ndarray:
    """Each patch's ΔE00 predicted by a fit on the other folds (leave-n/k-out)."""
    rgb01, lab = np.asarray(rgb01, float), np.asarray(lab, float)
    out = np.empty(len(lab))
    for test in folds(len(lab), k):
        train = np.setdiff1d(np.arange(len(lab)), test)
        out[test] = delta_e00(apply(rgb01[test], fit(rgb01[train], lab[train], polynomial), polynomial), lab[test])
    return out


def timed(fn, *args, repeats: int = 7) -> float:
    """Median wall time of fn(*args) in seconds."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def learning_curve(rgb01, lab, polynomial: int, sizes, draws: int = 10, seed: int = 11):
    """Mean ΔE00 on the patches left out, trained on n random patches, averaged over ``draws`` draws per n."""
    rgb01, lab = np.asarray(rgb01, float), np.asarray(lab, float)
    rng = np.random.default_rng(seed)
    out = []
    for n in sizes:
        errs = []
        for _ in range(draws):
            perm = rng.permutation(len(lab))
            tr, te = perm[:n], perm[n:]
            errs.append(delta_e00(apply(rgb01[te], fit(rgb01[tr], lab[tr], polynomial), polynomial), lab[te]).mean())
        out.append(float(np.mean(errs)))
    return out
