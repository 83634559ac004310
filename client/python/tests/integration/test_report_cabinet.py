"""The report of cabinet-grid runs (§6.2) on the simulated lab: every map, window table, proportionality and
lamp number recomputed here from the readings as stored in the daemon's SQLite file, the published numbers
found in the dissertation's text, every figure shown by headless Chromium.

A full 8 × 10 D65 grid at the dissertation's four dimmer levels gives windows comparable cell by cell with
Tables 3-6; a small grid of three lamps covers figs. 43-46."""
from __future__ import annotations

import os
import re
import unittest
from pathlib import Path

import numpy as np

from report_support import ReportCase, check_in_browser, make_report, parse

THESIS = Path(os.environ.get("COLORLAB_DISSERTATION", "/work/shared/seed/ulbricht-2006-dissertation.txt"))


def short(run_id):
    return "r" + run_id.replace("-", "")[-12:]


def thesis_lines():
    if not THESIS.exists():
        raise unittest.SkipTest(f"{THESIS} absent")
    return THESIS.read_text().splitlines()


def thesis_window_table(lines, number):
    """Rows i -> tab fields of Table <number> in the text (the first row so labelled above its caption)."""
    cap = next(k for k, l in enumerate(lines) if l.startswith(f"Table {number}:") and "submatrices" in l)
    head = max(k for k in range(cap) if lines[k].startswith("$i \\setminus j$"))
    rows = {}
    for l in lines[head + 1:cap]:
        m = re.match(r"^(\d)\t", l)
        if m and m[1] not in rows:
            rows[m[1]] = l.split("\t")[1:]
    return rows


def thesis_number(lines, pattern):
    for l in lines:
        m = re.search(pattern, l)
        if m:
            return float(m[1])
    raise AssertionError(pattern)


def stored_grids(daemon, run_id):
    out = {}
    for m in daemon.stored_measurements(run_id):
        lamp, level, spot = re.match(r"^L/([^/]+)/D([\d.]+)/(r\d+c\d+)$", m["step"]).groups()
        r, c = map(int, re.match(r"r(\d+)c(\d+)", spot).groups())
        self_check = m["data"]
        assert (self_check["row"], self_check["col"], self_check["lamp"]) == (r, c, lamp)
        out.setdefault(lamp, {}).setdefault(float(level), {})[(r, c)] = m["value"]
    grids = {}
    for lamp, levels in out.items():
        for level, spots in levels.items():
            rows = max(r for r, _ in spots) + 1
            cols = max(c for _, c in spots) + 1
            g = np.array([[spots[(r, c)] for c in range(cols)] for r in range(rows)])
            grids.setdefault(lamp, {})[level] = g
    return grids


def windows(half, wr, wc):
    full = np.hstack([half, half[:, ::-1]])
    return np.array([[np.std(full[i:i + wr, j:j + wc], ddof=1) for j in range(full.shape[1] - wc + 1)]
                     for i in range(full.shape[0] - wr + 1)])


def difference_map(half):
    full = np.hstack([half, half[:, ::-1]])
    return full - full.min()


class CabinetReport(ReportCase):
    SEED = 7

    @classmethod
    def campaigns(cls, d):
        cls.full = d.run_to_end("cabinet-grid", lamps=["D65"], dimmer_levels=[100, 50, 25, 15], settle_s=0)["run_id"]
        cls.small = d.run_to_end("cabinet-grid", rows=2, cols=5, lamps=["D65", "TL84", "CWF"], dimmer_levels=[100, 50],
                                 settle_s=0)["run_id"]
        cls.path = make_report(d, [cls.full, cls.small], "cabinet-grid")
        cls.tables, cls.ids = parse(cls.path)

    def check_run(self, run_id):
        grids = stored_grids(self.daemon, run_id)
        s = short(run_id)
        maps = self.tables[f"{s}-maps"]
        lamps = self.tables[f"{s}-lamps"]
        for lamp, levels in grids.items():
            top = max(levels)
            for level, g in levels.items():
                rows, cols = g.shape
                w = windows(g, min(4, rows), min(5, cols))
                key = f"{lamp}-{level:g}-measured"
                self.assertAlmostEqual(maps[(key, "min", "measured")], g.min(), places=9)
                self.assertAlmostEqual(maps[(key, "max", "measured")], g.max(), places=9)
                self.assertAlmostEqual(maps[(key, "range", "measured")], g.max() - g.min(), places=9)
                self.assertAlmostEqual(maps[(key, "best window stdev", "measured")], w.min(), places=9)
                self.assertAlmostEqual(maps[(key, "worst window stdev", "measured")], w.max(), places=9)
                bi, bj = int(maps[(key, "best window row", "measured")]), int(maps[(key, "best window col", "measured")])
                self.assertAlmostEqual(w[bi, bj], w.min(), places=9)
                tid = (f"{s}-table{ {100: 3, 50: 4, 25: 5, 15: 6}[int(level)] }" if lamp == "D65"
                       else f"{s}-windows-{lamp}-{level:g}")
                t = self.tables[tid]
                for i in range(w.shape[0]):
                    for j in range(w.shape[1]):
                        self.assertAlmostEqual(t[(f"{i}-measured", str(j), "measured")], w[i, j], places=9, msg=tid)
                if level != top:
                    err = np.abs(difference_map(levels[top]) - difference_map(g) * top / level).max()
                    self.assertAlmostEqual(self.tables[f"{s}-dimmer"][(f"{lamp}-measured", f"{level:g}", "measured")],
                                           err, places=9)
            g = levels[top]
            w = windows(g, min(4, g.shape[0]), min(5, g.shape[1]))
            for col, expect in (("min", g.min()), ("max", g.max()), ("range", g.max() - g.min()),
                                ("best window stdev", w.min()), ("worst window stdev", w.max())):
                self.assertAlmostEqual(lamps[(f"{lamp}-measured", col, "measured")], expect, places=9, msg=col)
        return grids

    def test_full_grid_against_tables_3_to_6(self):
        grids = self.check_run(self.full)
        self.assertEqual(grids["D65"][100].shape, (8, 10))
        lines = thesis_lines()
        s = short(self.full)
        compared = 0
        for level, number in ((100, 3), (50, 4), (25, 5), (15, 6)):
            text = thesis_window_table(lines, number)
            w = windows(grids["D65"][level], 4, 5)
            self.assertEqual(w.shape, (5, 16))
            t = self.tables[f"{s}-table{number}"]
            for i in range(5):
                for j in range(16):
                    p = t.get((f"{i}-published", str(j), "published"))
                    if p is None:
                        continue  # illegible in the text: shown as a dash
                    self.assertEqual(p, float(text[str(i)][j].split()[0]), f"Table {number} ({i}, {j})")
                    self.assertAlmostEqual(t[(f"{i}-diff", str(j), "difference")], w[i, j] - p, places=9)
                    compared += 1
        self.assertGreater(compared, 250)
        maps = self.tables[f"{s}-maps"]
        self.assertEqual(maps[("D65-100-published", "min", "published")], thesis_number(lines, r"minimum luminance of ([\d.]+) cd"))
        self.assertEqual(maps[("D65-100-published", "max", "published")], thesis_number(lines, r"maximum luminance of ([\d.]+) cd"))
        self.assertEqual(maps[("D65-100-published", "range", "published")], thesis_number(lines, r"whole area is ([\d.]+) cd"))
        best = dict(zip((100, 50, 25, 15), map(float, re.search(
            r"deviations are ([\d.]+) for dimmer setting 100%, ([\d.]+) for 50%, ([\d.]+) for 25% and ([\d.]+) for 15%",
            "\n".join(lines)).groups())))
        for level, p in best.items():
            self.assertEqual(maps[(f"D65-{level}-published", "best window stdev", "published")], p)
            self.assertAlmostEqual(maps[(f"D65-{level}-diff", "best window stdev", "difference")],
                                   windows(grids["D65"][level], 4, 5).min() - p, places=9)
        dim = self.tables[f"{s}-dimmer"]
        errs = re.search(r"maximum absolute error is ([\d.]+)\. .* ([\d.]+) for 25% and ([\d.]+) for 15%", "\n".join(lines))
        for level, p in zip((50, 25, 15), map(float, errs.groups())):
            self.assertEqual(dim[("D65-published", str(level), "published")], p)

    def test_three_lamps(self):
        grids = self.check_run(self.small)
        self.assertEqual(set(grids), {"D65", "TL84", "CWF"})
        lines = thesis_lines()
        worst = re.search(r"maximum values are ([\d.]+) cd/m\^2 \(840\) and ([\d.]+) cd/m\^2 \(CWF\)", "\n".join(lines))
        lamps = self.tables[f"{short(self.small)}-lamps"]
        self.assertEqual(lamps[("TL84-published", "worst window stdev", "published")], float(worst[1]))
        self.assertEqual(lamps[("CWF-published", "worst window stdev", "published")], float(worst[2]))

    def test_opens_in_chromium_with_every_figure(self):
        figs = [f"{short(self.full)}-fig{n}" for n in (36, 37, 38, 39, 40, 41, 42)]
        figs += [f"{short(self.small)}-fig{n}" for n in (36, 37, 38, 39, 42, 43, 44, 45, 46)]
        check_in_browser(self, self.path, figs, "cabinet-grid")


if __name__ == "__main__":
    unittest.main()
