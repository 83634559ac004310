#!/usr/bin/python3
"""The work of bench_analysis_polyfit in numpy: all 26 term sets, each fitted to the 140 SG test vectors by
column-equilibrated QR, with training and leave-one-out (leverage identity) errors in dE76 and dE00.

usage: polyfit_numpy.py [testvec_sg140_canon20d_d50_argyll.csv] [repetitions]
Prints the median time of one pass over all sets in milliseconds."""
import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

WHITE = np.array([96.42, 100.0, 82.49])


def mono(spec):
    out = []
    for s in spec:
        e = [0.0, 0.0, 0.0]
        if s != "1":
            i = 0
            while i < len(s):
                c = "rgb".index(s[i])
                p = 1
                if i + 1 < len(s) and s[i + 1].isdigit():
                    p = int(s[i + 1])
                    i += 1
                e[c] += p
                i += 1
        out.append(e)
    return out


def term_sets():
    d = {
        1: "r g b", 2: "r g b rgb 1", 3: "r g b rg rb gb", 4: "r g b rg rb gb rgb 1",
        5: "r g b rg rb gb r2 g2 b2", 6: "r g b rg rb gb r2 g2 b2 rgb 1",
        7: "r g b rg rb gb r2 g2 b2 r3 g3 b3 1",
        8: "r g b rg rb gb r2 g2 b2 r2g2 r2b2 g2b2 r2g2b2 r3 g3 b3 r3g3 r3b3 g3b3 1",
        9: "r g b rg rb gb r2 g2 b2 r3 g3 b3 r4 g4 b4 1",
        10: "r g b rg rb gb rgb r2 g2 b2 r2g2 r2b2 g2b2 r2g2b2 r3 g3 b3 r3g3 r3b3 g3b3 r3g3b3 r4 g4 b4 r4g4 r4b4 g4b4 r4g4b4 1",
        11: "r g b rg rb gb r2 g2 b2 r3 g3 b3 r4 g4 b4 r5 g5 b5 1",
    }
    sets = [mono(v.split()) for _, v in sorted(d.items())]
    base = "r g b rg rb gb r2 g2 b2 rgb".split()
    h = {3: "r g b", 5: "r g b rgb 1", 7: "r g b rg rb gb rgb", 8: "r g b rg rb gb rgb 1",
         10: "r g b rg rb gb r2 g2 b2 1", 11: "r g b rg rb gb r2 g2 b2 rgb 1",
         14: "r g b rg rb gb r2 g2 b2 rgb r3 g3 b3 1",
         16: " ".join(base + "r2g g2b b2r r3 g3 b3".split()), 17: " ".join(base + "r2g g2b b2r r3 g3 b3 1".split()),
         19: " ".join(base + "r2g g2b b2r r2b g2r b2g r3 g3 b3".split()),
         20: " ".join(base + "r2g g2b b2r r2b g2r b2g r3 g3 b3 1".split())}
    sets += [mono(v.split()) for _, v in sorted(h.items())]
    roots = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    r2 = [[1, 1, 0], [0, 1, 1], [1, 0, 1]]
    r3 = [[1, 2, 0], [0, 1, 2], [1, 0, 2], [2, 1, 0], [0, 2, 1], [2, 0, 1], [1, 1, 1]]
    r4 = [[3, 1, 0], [3, 0, 1], [1, 3, 0], [0, 3, 1], [1, 0, 3], [0, 1, 3], [2, 1, 1], [1, 2, 1], [1, 1, 2]]
    norm = lambda l: [[x / sum(e) for x in e] for e in l]
    acc = list(roots)
    for extra in (None, r2, r3, r4):
        if extra is not None:
            acc = acc + norm(extra)
        sets.append(list(acc))
    return [np.array(s, dtype=float) for s in sets]


def expand(rgb, exps):
    x = np.maximum(rgb, 0.0)
    return np.prod(x[:, None, :] ** exps[None, :, :], axis=2)


def lab(xyz):
    t = xyz / WHITE
    d = 6 / 29
    f = np.where(t > d ** 3, np.cbrt(t), t / (3 * d * d) + 4 / 29)
    return np.stack([116 * f[:, 1] - 16, 500 * (f[:, 0] - f[:, 1]), 200 * (f[:, 1] - f[:, 2])], axis=1)


def de2000(p, q):
    L1, a1, b1 = p.T
    L2, a2, b2 = q.T
    C1, C2 = np.hypot(a1, b1), np.hypot(a2, b2)
    Cb7 = ((C1 + C2) / 2) ** 7
    G = 0.5 * (1 - np.sqrt(Cb7 / (Cb7 + 25.0 ** 7)))
    a1p, a2p = (1 + G) * a1, (1 + G) * a2
    C1p, C2p = np.hypot(a1p, b1), np.hypot(a2p, b2)
    h1 = np.degrees(np.arctan2(b1, a1p)) % 360
    h2 = np.degrees(np.arctan2(b2, a2p)) % 360
    dL, dC = L2 - L1, C2p - C1p
    dh = h2 - h1
    dh = np.where(dh > 180, dh - 360, np.where(dh < -180, dh + 360, dh))
    dh = np.where(C1p * C2p == 0, 0, dh)
    dH = 2 * np.sqrt(C1p * C2p) * np.sin(np.radians(dh / 2))
    Lb, Cbp = (L1 + L2) / 2, (C1p + C2p) / 2
    hs = h1 + h2
    hb = np.where(np.abs(h1 - h2) <= 180, hs / 2, np.where(hs < 360, (hs + 360) / 2, (hs - 360) / 2))
    hb = np.where(C1p * C2p == 0, hs, hb)
    T = (1 - 0.17 * np.cos(np.radians(hb - 30)) + 0.24 * np.cos(np.radians(2 * hb))
         + 0.32 * np.cos(np.radians(3 * hb + 6)) - 0.20 * np.cos(np.radians(4 * hb - 63)))
    dT = 30 * np.exp(-(((hb - 275) / 25) ** 2))
    Rc = 2 * np.sqrt(Cbp ** 7 / (Cbp ** 7 + 25.0 ** 7))
    SL = 1 + 0.015 * (Lb - 50) ** 2 / np.sqrt(20 + (Lb - 50) ** 2)
    SC, SH = 1 + 0.045 * Cbp, 1 + 0.015 * Cbp * T
    RT = -np.sin(np.radians(2 * dT)) * Rc
    tL, tC, tH = dL / SL, dC / SC, dH / SH
    return np.sqrt(tL ** 2 + tC ** 2 + tH ** 2 + RT * tC * tH)


def one_pass(rgb, xyz, ref_lab, sets):
    out = []
    for exps in sets:
        X = expand(rgb, exps)
        d = np.linalg.norm(X, axis=0)
        Q, R = np.linalg.qr(X / d)
        M = np.linalg.solve(R, Q.T @ xyz) / d[:, None]
        fit = X @ M
        h = np.sum(Q * Q, axis=1)
        loo = xyz - (xyz - fit) / (1 - h)[:, None]
        for pred in (fit, loo):
            pl = lab(pred)
            out.append((np.linalg.norm(pl - ref_lab, axis=1).mean(), de2000(ref_lab, pl).mean()))
    return out


def main():
    here = Path(__file__).resolve()
    default = here.parents[3] / "shared" / "data" / "testvec_sg140_canon20d_d50_argyll.csv"
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else default
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 50
    with open(path) as f:
        rows = list(csv.DictReader(f))
    rgb = np.array([[float(r[c]) for c in "RGB"] for r in rows])
    xyz = np.array([[float(r[c + "_D50"]) for c in "XYZ"] for r in rows])
    ref = np.array([[float(r[c + "_D50"]) for c in ("L", "a", "b")] for r in rows])
    sets = term_sets()
    assert len(sets) == 26, len(sets)
    one_pass(rgb, xyz, ref, sets)
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        res = one_pass(rgb, xyz, ref, sets)
        times.append(time.perf_counter() - t0)
    times.sort()
    print(f"numpy {np.__version__}: all 26 sets with LOO on {len(rows)} patches: median {1000 * times[len(times) // 2]:.2f} ms "
          f"(min {1000 * times[0]:.2f} ms, {reps} runs); rootpoly:3 LOO mean dE00 {res[2 * 24 + 1][1]:.4f}")


if __name__ == "__main__":
    main()
