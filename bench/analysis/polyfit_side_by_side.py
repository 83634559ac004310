#!/usr/bin/python3
"""colorlab against numpy on the same polynomial work, interleaved in one harness and one run.

The work: all 26 term sets fitted to the 140 SG test vectors with leave-one-out (ΔE76 and ΔE00), one "pass".
The C++ half is bench_analysis_polyfit --serve, a child process kept warm for the whole run; the numpy half is
polyfit_numpy.one_pass in this process. Both time each pass alone with a monotonic clock around exactly one pass
(steady_clock in C++, perf_counter here), after one warm-up pass each. Rounds alternate which side goes first
(C++ then numpy, numpy then C++, ...), each side running --passes passes per round while the other waits blocked
on a pipe. Per round the ratio is numpy's median pass over colorlab's; both sides' rootpoly:3 LOO mean ΔE00 must
agree (the same work).

usage: polyfit_side_by_side.py [--build build] [--csv testvec_sg140_canon20d_d50_argyll.csv] [--rounds 20] [--passes 5]
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import polyfit_numpy  # noqa: E402  (the numpy half: the same file the stand-alone numpy bench runs)


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def main():
    here = Path(__file__).resolve()
    p = argparse.ArgumentParser()
    p.add_argument("--build", default=str(here.parents[2] / "build"))
    p.add_argument("--csv", default=str(here.parents[3] / "shared" / "data" / "testvec_sg140_canon20d_d50_argyll.csv"))
    p.add_argument("--rounds", type=int, default=20)
    p.add_argument("--passes", type=int, default=5)
    a = p.parse_args()
    if not Path(a.csv).exists():
        print("skipped: %s not present (../shared/data)" % a.csv)
        return 0

    with open(a.csv) as f:
        rows = list(csv.DictReader(f))
    rgb = np.array([[float(r[c]) for c in "RGB"] for r in rows])
    xyz = np.array([[float(r[c + "_D50"]) for c in "XYZ"] for r in rows])
    ref = np.array([[float(r[c + "_D50"]) for c in ("L", "a", "b")] for r in rows])
    sets = polyfit_numpy.term_sets()

    def numpy_block(n):
        times, res = [], None
        for _ in range(n):
            t0 = time.perf_counter()
            res = polyfit_numpy.one_pass(rgb, xyz, ref, sets)
            times.append(time.perf_counter() - t0)
        return res[2 * 24 + 1][1], times

    cpp = subprocess.Popen([os.path.join(a.build, "bin", "bench_analysis_polyfit"), "--serve", a.csv],
                           stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)

    def cpp_block(n):
        cpp.stdin.write("%d\n" % n)
        cpp.stdin.flush()
        parts = cpp.stdout.readline().split()
        if not parts:
            raise SystemExit("bench_analysis_polyfit --serve stopped")
        return float(parts[0]), [int(x) / 1e9 for x in parts[1:]]

    numpy_block(1)  # warm-up (the C++ half warms up on start)
    load_before = loadavg()
    t_start = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    all_c, all_n, ratios = [], [], []
    checks = set()
    for r in range(a.rounds):
        order = ("cpp", "numpy") if r % 2 == 0 else ("numpy", "cpp")
        got = {}
        for side in order:
            got[side] = cpp_block(a.passes) if side == "cpp" else numpy_block(a.passes)
        checks.add(("colorlab", round(got["cpp"][0], 4)))
        checks.add(("numpy", round(got["numpy"][0], 4)))
        mc, mn = statistics.median(got["cpp"][1]), statistics.median(got["numpy"][1])
        all_c += got["cpp"][1]
        all_n += got["numpy"][1]
        ratios.append(mn / mc)
    load_after = loadavg()
    cpp.stdin.close()
    cpp.wait()

    values = {v for _, v in checks}
    print("polyfit side by side: %s, %d rounds × %d passes per side, alternating first; numpy %s" %
          (t_start, a.rounds, a.passes, np.__version__))
    print("load average before %s, after %s" % (load_before, load_after))
    print("same work: rootpoly:3 LOO mean dE00 %s" % ", ".join("%s %.4f" % c for c in sorted(checks)))
    ms = lambda v: 1000 * v
    print("%-10s median %.2f ms  (min %.2f, max %.2f) per pass of all 26 sets" %
          ("colorlab", ms(statistics.median(all_c)), ms(min(all_c)), ms(max(all_c))))
    print("%-10s median %.2f ms  (min %.2f, max %.2f)" %
          ("numpy", ms(statistics.median(all_n)), ms(min(all_n)), ms(max(all_n))))
    print("ratio numpy/colorlab per round: median %.2fx (min %.2fx, max %.2fx over %d rounds)" %
          (statistics.median(ratios), min(ratios), max(ratios), len(ratios)))
    print("per round (numpy/colorlab, in order): " + " ".join("%.2f" % r for r in ratios))
    if len(values) != 1:
        print("MISMATCH: the two halves did not compute the same figure")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
